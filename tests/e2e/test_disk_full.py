"""A run whose disk fills up (docs/recording.md, "Disk full"; issue 30).

The run folder is put on a small tmpfs (mounted here, as root; skipped with the reason when
mount is not permitted):
- Recording: `convoy run --record-blobs` of an engine that makes 200 kB of random bytes every
  step fills 2 MiB within a few steps. The run ends with exit 2 and one message "no space left
  writing RUN/recording.mcap", no engine is left, the recording is readable by every reader up
  to its last whole chunk (as many messages as the message says), and summary.json is whole
  JSON that says why the run ended.
- NoRoom: a disk with no room at all from the start (no recording): exit 2 and "no space left
  writing .../config.json", no engine started; whatever it could write is not garbage.

Each test prints what it found.
"""
import json
import os
import re
import shutil
import subprocess
import textwrap
import unittest

from e2e_util import E2ETestCase
import test_recording_faults as trf  # readers (module only: its tests are not run here)

# 200 kB of random bytes a step, as a numpy array (a blob: recorded with --record-blobs).
SPEW = textwrap.dedent('''\
    import numpy as np
    from nrp_core.engines.python_json import EngineScript

    class Script(EngineScript):
        def initialize(self):
            self._rng = np.random.default_rng(30)
            self._registerDataPack("noise")
            self._setDataPack("noise", {"t": 0})

        def runLoop(self, timestep_ns):
            self._setDataPack("noise", {"t": self._time_ns,
                                        "bytes": self._rng.integers(0, 256, 200_000, dtype=np.uint8)})
    ''')

READ_TF = textwrap.dedent('''\
    from nrp_core import *

    @EngineDataPack(keyword="noise", id=DataPackIdentifier("noise", "spew"))
    @TransceiverFunction("spew")
    def read(noise):
        return []
    ''')


def config(timeout):
    return {"SimulationName": "disk_full", "SimulationTimeout": timeout,
            "EngineConfigs": [{"EngineType": "python_json", "EngineName": "spew",
                               "PythonFileName": "spew.py", "EngineTimestep": 0.01}],
            "DataPackProcessingFunctions": [{"Name": "read", "FileName": "read_tf.py"}]}


class SmallDiskTestCase(trf.ReadersTestCase):
    SIZE = "2m"

    def setUp(self):
        super().setUp()
        self.disk = os.path.join(self.dir, "disk")
        os.makedirs(self.disk)
        r = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=" + self.SIZE, "tmpfs", self.disk],
                           stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        if r.returncode != 0:
            why = "cannot mount a tmpfs (%s): %s" % ("not root" if os.geteuid() else "not permitted",
                                                     r.stdout.strip())
            print("\n[skipped: %s]" % why)
            self.skipTest(why)
        self.addCleanup(self.unmount)
        self.run_dir = os.path.join(self.disk, "run")
        self.write("spew.py", SPEW)
        self.write("read_tf.py", READ_TF)

    def unmount(self):
        # After tearDown killed whatever was left (its rmtree could not remove the mount
        # point); lazily, should something still hold it.
        subprocess.run(["umount", "-l", self.disk], stdout=subprocess.DEVNULL,
                       stderr=subprocess.DEVNULL)
        if not os.environ.get("CONVOY_E2E_KEEP"):
            shutil.rmtree(self.dir, ignore_errors=True)

    def summary_or_why(self):
        """summary.json as JSON; fails naming what is wrong with it."""
        path = os.path.join(self.run_dir, "summary.json")
        self.assertTrue(os.path.isfile(path), "no summary.json: %s" % os.listdir(self.run_dir))
        with open(path, "rb") as f:
            raw = f.read()
        try:
            return json.loads(raw)
        except ValueError as e:
            self.fail("summary.json is not JSON (%d bytes: %r...): %s" % (len(raw), raw[:120], e))


class Recording(SmallDiskTestCase):
    def test_recording_fills_the_disk(self):
        self.write_config(config(timeout=5))
        r = self.run_convoy("--record-blobs", timeout=60)
        mcap = os.path.join(self.run_dir, "recording.mcap")
        self.assertExit(r, 2)
        self.assertOneError(r)
        self.assertStderrHas(r, "error: no space left writing %s" % mcap)
        self.assertNoEngineLeft(within=5.0)
        said = int(re.search(r"keeps its first (\d+) messages", r.stderr).group(1))
        # Readable up to its last whole chunk, by every reader, as the message said.
        rec, msgs, warned = trf.python_read(mcap)
        self.assertFalse(rec.complete)
        self.assertEqual(len(warned), 1)
        self.assertEqual(rec.incomplete, "no Data End record (the writer stopped)",
                         "the file is cut back to its last whole record")
        self.assertEqual(len(msgs), said)
        noise = [m for m in msgs if m[0] == "spew/noise"]
        self.assertGreater(len(noise), 1)
        self.assertEqual([m[1] for m in noise], list(range(len(noise))))  # no gap
        self.assertReadersAgree(mcap, msgs)
        # summary.json: whole, with the exit code and the reason.
        summary = self.summary_or_why()
        self.assertEqual(summary.get("exit_code"), 2, summary)
        self.assertIn("no space left writing " + mcap, summary.get("error", ""))
        df = os.statvfs(self.disk)
        print("\n[2 MiB disk filled by the recording: exit 2, %d messages (%d bytes) readable by "
              "Python, C++%s; summary.json whole; %d kB free after the run]"
              % (len(msgs), os.path.getsize(mcap), "" if self.node_why else ", @mcap/core",
                 df.f_bavail * df.f_frsize // 1024))


class NoRoom(SmallDiskTestCase):
    SIZE = "256k"

    def test_a_full_disk_from_the_start(self):
        # The run folder exists; then the disk is filled to its last byte.
        os.makedirs(os.path.join(self.run_dir, "logs"))
        fd = os.open(os.path.join(self.disk, "filler"), os.O_WRONLY | os.O_CREAT, 0o644)
        try:
            while os.write(fd, b"\0" * 4096) > 0:
                pass
        except OSError:
            pass
        finally:
            os.close(fd)
        self.write_config(config(timeout=0.3))
        r = self.run_convoy(timeout=60)
        # No crash and no hang: exit 2 with one message naming the file that found no room
        # (config.json, the first the run writes), and no engine started.
        self.assertExit(r, 2)
        self.assertStderrHas(r, "no space left writing", os.path.join(self.run_dir, "config.json"))
        self.assertNoEngineLeft(within=5.0)
        found = {}
        for name in ("summary.json", "steps.csv", "config.json", "logs/coordinator.log"):
            path = os.path.join(self.run_dir, name)
            found[name] = os.path.getsize(path) if os.path.exists(path) else None
        # What was written is not garbage: summary.json, when there, is whole JSON.
        if found["summary.json"]:
            self.summary_or_why()
        print("\n[a full disk, no recording: exit %d, stderr %r; sizes %s]"
              % (r.code, r.stderr.strip().splitlines()[-1:] if r.stderr.strip() else "", found))


if __name__ == "__main__":
    unittest.main()
