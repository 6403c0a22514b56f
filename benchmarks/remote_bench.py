#!/usr/bin/python3
"""Remote-engine benchmark: NRP-Core's a_tiny_json experiment with its second engine as a
remote engine server (EmptyLaunchCommand, gRPC on localhost), plain, with a token, over TLS,
and over TLS with a token. Prints loop steps/s (median of --runs, the runs interleaved).

  /usr/bin/python3 benchmarks/remote_bench.py [--runs 5] [--seconds 20]

The forked (socket) engine of the same experiment is printed first for reference.
Certificates are made with openssl in a temporary folder.
"""

import argparse
import json
import os
import shutil
import socket
import statistics
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def openssl(d, *args):
    subprocess.run(["openssl"] + list(args), cwd=d, check=True, stdout=subprocess.DEVNULL,
                   stderr=subprocess.DEVNULL)


def make_pki(d):
    ec = ["-newkey", "ec", "-pkeyopt", "ec_paramgen_curve:prime256v1", "-nodes"]
    openssl(d, "req", "-x509", *ec, "-keyout", "ca.key", "-out", "ca.pem", "-days", "2", "-subj", "/CN=ca")
    openssl(d, "req", *ec, "-keyout", "server.key", "-out", "server.csr", "-subj", "/CN=localhost")
    with open(os.path.join(d, "san.ext"), "w") as f:
        f.write("subjectAltName=DNS:localhost,IP:127.0.0.1\n")
    openssl(d, "x509", "-req", "-in", "server.csr", "-CA", "ca.pem", "-CAkey", "ca.key",
            "-CAcreateserial", "-out", "server.pem", "-days", "2", "-extfile", "san.ext")


def run_variant(args, work, variant, pki):
    exp = os.path.join(work, "a_tiny_json")
    with open(os.path.join(exp, "simulation_config.json")) as f:
        cfg = json.load(f)
    cfg["SimulationTimeout"] = args.seconds
    server = None
    if variant != "forked":
        port = free_port()
        remote = cfg["EngineConfigs"][1]
        remote["EngineLaunchCommand"] = {"LaunchType": "EmptyLaunchCommand"}
        remote["ServerAddress"] = "localhost:%d" % port
        flags, env = [], dict(os.environ)
        env.pop("CONVOY_ENGINE_TOKEN", None)
        if "tls" in variant:
            remote["ServerTLS"] = {"CACertificate": os.path.join(pki, "ca.pem")}
            flags += ["--tls-cert", os.path.join(pki, "server.pem"), "--tls-key", os.path.join(pki, "server.key")]
        if "token" in variant:
            remote["AuthToken"] = "bench-token"
            env["CONVOY_ENGINE_TOKEN"] = "bench-token"
        server = subprocess.Popen([os.path.join(args.bin_dir, "convoy-engine-python_json"), "--address",
                                   "localhost:%d" % port] + flags, cwd=exp, env=env,
                                  stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    path = os.path.join(exp, "bench_config.json")
    with open(path, "w") as f:
        json.dump(cfg, f)
    r = subprocess.run([os.path.join(args.bin_dir, "convoy"), "run", "-q", "-c", path, "--run-dir",
                        os.path.join(work, "runs", variant)], capture_output=True, text=True)
    if server:
        try:
            server.wait(timeout=10)
        except subprocess.TimeoutExpired:
            server.kill()
            server.wait()
    if r.returncode != 0:
        sys.exit("run failed (%s):\n%s" % (variant, r.stderr))
    with open(os.path.join(exp, "timing_python_2.json")) as f:
        return json.load(f)["steps_per_s"]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--seconds", type=float, default=20, help="simulated seconds a run (0.01 s steps)")
    ap.add_argument("--bench-dir", default=os.path.join(os.path.dirname(REPO), "shared", "nrp-bench"))
    ap.add_argument("--bin-dir", default=os.path.join(REPO, "build", "bin"))
    args = ap.parse_args()
    work = tempfile.mkdtemp(prefix="convoy-remote-")
    try:
        shutil.copytree(args.bench_dir, work, dirs_exist_ok=True)
        for root, dirs, files in os.walk(work):
            for n in dirs + files:
                os.chmod(os.path.join(root, n), 0o755 if n in dirs else 0o644)
        pki = os.path.join(work, "pki")
        os.makedirs(pki)
        make_pki(pki)
        variants = ["forked", "plain", "token", "tls", "tls+token"]
        results = {v: [] for v in variants}
        for _ in range(args.runs):
            for v in variants:
                results[v].append(run_variant(args, work, v, pki))
        plain = statistics.median(results["plain"])
        for v in variants:
            med = statistics.median(results[v])
            print("a_tiny_json, remote engine %-10s loop steps/s median %8.1f (runs: %s)  %.2f of plain gRPC" % (
                v if v != "forked" else "(forked)", med, ", ".join("%.0f" % x for x in results[v]), med / plain))
    finally:
        shutil.rmtree(work, True)


if __name__ == "__main__":
    main()
