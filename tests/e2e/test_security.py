"""End-to-end tests of remote engines' security: an engine server listens beyond the loopback
only with TLS or a token (or --insecure, with a warning); TLS with the right and the wrong
certificates; the token, right, wrong or missing, on both sides, never written anywhere;
datapacks are data only.

Run with Debian's /usr/bin/python3 -m unittest test_security."""

import json
import os
import pickle
import shutil
import subprocess
import tempfile
import textwrap
import time
import unittest

from e2e_util import free_port

from test_core import BIN_DIR, RECORDER, RELAY, Experiment

ENGINE = os.path.join(BIN_DIR, "convoy-engine-python_json")



def openssl(*args, cwd):
    subprocess.run(["openssl"] + list(args), cwd=cwd, check=True, stdout=subprocess.DEVNULL,
                   stderr=subprocess.DEVNULL)


def make_ca(d, name):
    openssl("req", "-x509", "-newkey", "ec", "-pkeyopt", "ec_paramgen_curve:prime256v1", "-nodes",
            "-keyout", name + ".key", "-out", name + ".pem", "-days", "2", "-subj", "/CN=" + name,
            cwd=d)


def make_cert(d, name, ca, san="DNS:localhost,IP:127.0.0.1"):
    openssl("req", "-newkey", "ec", "-pkeyopt", "ec_paramgen_curve:prime256v1", "-nodes",
            "-keyout", name + ".key", "-out", name + ".csr", "-subj", "/CN=" + name, cwd=d)
    with open(os.path.join(d, name + ".ext"), "w") as f:
        f.write("subjectAltName=%s\n" % san)
    openssl("x509", "-req", "-in", name + ".csr", "-CA", ca + ".pem", "-CAkey", ca + ".key",
            "-CAcreateserial", "-out", name + ".pem", "-days", "2", "-extfile", name + ".ext", cwd=d)


class RemoteEngineSecurity(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.pki = tempfile.mkdtemp(prefix="convoy-pki-")
        make_ca(cls.pki, "ca")
        make_ca(cls.pki, "other_ca")
        make_cert(cls.pki, "server", "ca")
        make_cert(cls.pki, "client", "ca", san="DNS:client")
        make_cert(cls.pki, "stranger", "other_ca", san="DNS:client")

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.pki, True)

    def pem(self, name):
        return os.path.join(self.pki, name)

    def start_server(self, ex, address, *flags, env=None):
        log = open(os.path.join(ex.dir, "server.log"), "w")
        server = subprocess.Popen([ENGINE, "--address", address] + list(flags), cwd=ex.dir,
                                  env=dict(os.environ, **(env or {})), stdout=log,
                                  stderr=subprocess.STDOUT)
        self.addCleanup(self.stop, server, log)
        return server

    def stop(self, server, log):
        if server.poll() is None:
            server.kill()
        server.wait()
        log.close()

    def server_log(self, ex):
        with open(os.path.join(ex.dir, "server.log")) as f:
            return f.read()

    def experiment(self, port, **remote):
        ex = Experiment(self)
        ex.engine("local", RECORDER.format(seed=0.3))
        ex.engine("remote", RECORDER.format(seed=0.6), ServerAddress="localhost:%d" % port,
                  EngineLaunchCommand={"LaunchType": "EmptyLaunchCommand"}, **remote)
        ex.function("tf_lr", RELAY.format(src="local", dst="remote"))
        ex.function("tf_rl", RELAY.format(src="remote", dst="local"))
        return ex

    def assert_ran(self, ex, server):
        server.wait(timeout=10)  # Shutdown ends the server
        remote = ex.records("remote")
        self.assertEqual(len(remote), 10)
        self.assertEqual(remote[-1]["got"]["t"], 90_000_000)

    # --- where a server may listen ---------------------------------------------------------

    def test_a_plain_server_listens_on_the_loopback_only(self):
        ex = Experiment(self)
        port = free_port()
        server = self.start_server(ex, "0.0.0.0:%d" % port)
        self.assertEqual(server.wait(timeout=10), 2)
        log = self.server_log(ex)
        self.assertIn("refusing to listen at 0.0.0.0:%d without TLS or a token" % port, log)
        self.assertIn("--insecure", log)

    def test_insecure_listens_anywhere_with_a_warning(self):
        port = free_port()
        ex = self.experiment(port)
        server = self.start_server(ex, "0.0.0.0:%d" % port, "--insecure")
        ex.run(0.1)
        self.assert_ran(ex, server)
        self.assertIn("warning: --insecure", self.server_log(ex))

    def test_a_token_lets_a_server_listen_anywhere(self):
        port = free_port()
        ex = self.experiment(port, AuthToken="s3cret-token-1")
        server = self.start_server(ex, "0.0.0.0:%d" % port, env={"CONVOY_ENGINE_TOKEN": "s3cret-token-1"})
        r = ex.run(0.1)
        self.assert_ran(ex, server)
        self.assertIn("token required", self.server_log(ex))
        # The token is written nowhere: not in the run folder, not in any log.
        for root, _, files in os.walk(os.path.join(ex.dir, "run")):
            for name in files:
                with open(os.path.join(root, name), errors="replace") as f:
                    self.assertNotIn("s3cret-token-1", f.read(), os.path.join(root, name))
        self.assertNotIn("s3cret-token-1", r.stderr + self.server_log(ex))
        with open(os.path.join(ex.dir, "run", "config.json")) as f:
            self.assertEqual(json.load(f)["EngineConfigs"][1]["AuthToken"], "***")

    # --- tokens ----------------------------------------------------------------------------

    def test_the_token_from_the_environment(self):
        port = free_port()
        ex = self.experiment(port)
        with open(os.path.join(ex.dir, "token"), "w") as f:
            f.write("tok-from-file\n")
        server = self.start_server(ex, "localhost:%d" % port, "--token-file", "token")
        old = os.environ.get("CONVOY_ENGINE_TOKEN")
        os.environ["CONVOY_ENGINE_TOKEN"] = "tok-from-file"
        try:
            ex.run(0.1)
        finally:
            if old is None:
                del os.environ["CONVOY_ENGINE_TOKEN"]
            else:
                os.environ["CONVOY_ENGINE_TOKEN"] = old
        self.assert_ran(ex, server)

    def test_a_wrong_or_missing_token_is_refused_on_both_sides(self):
        for given, said in (({"AuthToken": "not-the-token"}, "wrong token"), ({}, "no token")):
            port = free_port()
            ex = self.experiment(port, **given)
            self.start_server(ex, "localhost:%d" % port, env={"CONVOY_ENGINE_TOKEN": "the-token"})
            r = ex.run(0.1, expect=3)
            self.assertIn("engine 'remote'", r.stderr)
            self.assertIn("refused the coordinator", r.stderr)
            self.assertIn(said, r.stderr)
            self.assertIn("refused a call from", self.server_log(ex))
            self.assertIn(said, self.server_log(ex))
            self.assertNotIn("the-token", r.stderr + self.server_log(ex))
            self.assertNotIn("not-the-token", r.stderr + self.server_log(ex))

    # --- TLS -------------------------------------------------------------------------------

    def test_tls_with_the_right_and_the_wrong_certificate_authority(self):
        port = free_port()
        ex = self.experiment(port, ServerTLS={"CACertificate": self.pem("ca.pem")})
        server = self.start_server(ex, "localhost:%d" % port, "--tls-cert", self.pem("server.pem"),
                                   "--tls-key", self.pem("server.key"))
        ex.run(0.1)
        self.assert_ran(ex, server)
        self.assertIn("(TLS, no token)", self.server_log(ex))

        port = free_port()
        ex = self.experiment(port, ServerTLS={"CACertificate": self.pem("other_ca.pem")})
        self.start_server(ex, "localhost:%d" % port, "--tls-cert", self.pem("server.pem"),
                          "--tls-key", self.pem("server.key"))
        t0 = time.monotonic()
        r = ex.run(0.1, expect=3)
        self.assertLess(time.monotonic() - t0, 10)
        self.assertIn("engine 'remote'", r.stderr)
        self.assertIn("TLS handshake fails", r.stderr)

    def test_a_plain_coordinator_against_a_tls_server_is_told_why(self):
        port = free_port()
        ex = self.experiment(port)
        self.start_server(ex, "localhost:%d" % port, "--tls-cert", self.pem("server.pem"),
                          "--tls-key", self.pem("server.key"))
        r = ex.run(0.1, expect=3)
        self.assertIn("does it require TLS? then give ServerTLS", r.stderr)

    def test_client_certificates_when_the_server_requires_them(self):
        flags = ["--tls-cert", self.pem("server.pem"), "--tls-key", self.pem("server.key"),
                 "--tls-client-ca", self.pem("ca.pem")]
        port = free_port()
        ex = self.experiment(port, ServerTLS={"CACertificate": self.pem("ca.pem"),
                                              "ClientCertificate": self.pem("client.pem"),
                                              "ClientKey": self.pem("client.key")})
        server = self.start_server(ex, "0.0.0.0:%d" % port, *flags)
        ex.run(0.1)
        self.assert_ran(ex, server)
        for cert in ("stranger", None):  # signed by another authority, or none at all
            port = free_port()
            tls = {"CACertificate": self.pem("ca.pem")}
            if cert:
                tls.update(ClientCertificate=self.pem(cert + ".pem"), ClientKey=self.pem(cert + ".key"))
            ex = self.experiment(port, ServerTLS=tls)
            self.start_server(ex, "0.0.0.0:%d" % port, *flags)
            r = ex.run(0.1, expect=3)
            self.assertIn("TLS handshake fails", r.stderr)

    def test_bad_tls_settings_name_the_key(self):
        ex = self.experiment(free_port(), ServerTLS={"CACertificate": "missing.pem"})
        r = ex.run(0.1, expect=2)
        self.assertIn("/EngineConfigs/1/ServerTLS/CACertificate", r.stderr)
        ex = self.experiment(free_port(), ServerTLS={"ClientCertificate": self.pem("client.pem")})
        r = ex.run(0.1, expect=2)
        self.assertIn("/EngineConfigs/1/ServerTLS", r.stderr)
        self.assertIn("ClientCertificate and ClientKey go together", r.stderr)


# A TF that tries to make a datapack carry code: a pickle whose loading would write a file,
# and Python source. The engine receives them as bytes and a string; nothing runs them.
class _Trap:
    def __reduce__(self):
        return (open, ("PWNED", "w"))


DATA_ONLY_TF = textwrap.dedent("""\
    from nrp_core import *
    from nrp_core.data.nrp_json import *

    @TransceiverFunction("dst")
    def send():
        return [JsonDataPack("payload", "dst", {{"pickle": {pickle!r},
                                                 "code": "open('PWNED_TOO', 'w')"}})]
    """)

DATA_ONLY_DST = textwrap.dedent("""\
    import json, os
    from nrp_core.engines.python_json import EngineScript

    class Script(EngineScript):
        def initialize(self):
            self._registerDataPack("payload")

        def runLoop(self, timestep_ns):
            p = self._getDataPack("payload")
            if p is not None:
                with open("received.json", "w") as f:
                    json.dump({"pickle": type(p["pickle"]).__name__, "code": p["code"]}, f)
    """)


class DatapacksAreData(unittest.TestCase):
    def test_a_pickle_or_code_in_a_datapack_is_never_run(self):
        ex = Experiment(self)
        ex.engine("dst", DATA_ONLY_DST)
        ex.function("tf_send", DATA_ONLY_TF.format(pickle=pickle.dumps(_Trap())))
        ex.run(0.03)
        with open(os.path.join(ex.dir, "received.json")) as f:
            self.assertEqual(json.load(f), {"pickle": "bytes", "code": "open('PWNED_TOO', 'w')"})
        for name in ("PWNED", "PWNED_TOO"):
            self.assertFalse(os.path.exists(os.path.join(ex.dir, name)))


if __name__ == "__main__":
    unittest.main()
