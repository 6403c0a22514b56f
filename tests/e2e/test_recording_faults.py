"""A recording survives its writer (docs/recording.md, "Crash safety"; issue 30).

- KilledCoordinator: `convoy run --record` SIGKILLed at a few points of a run; every reader
  (python/convoy_mcap, Convoy's C++ reader through build/bin/convoy-mcap, the official
  @mcap/core's streaming reader through tools/mcap_check) reads the same messages: a prefix of
  the run with no gap, every message of the whole chunks, more the later the kill. While it
  runs, the file grows at least every ~1 s (a crash loses at most the open chunk).
- Truncated: a finished recording cut at seeded random byte offsets (and at every chunk's
  edges): each reader reads exactly the messages of the chunks before the cut, or refuses a
  file without its Header with one clear error; none crashes.

Each test prints what it killed or cut and what it found.
"""
import json
import os
import random
import shutil
import signal
import subprocess
import struct
import time
import unittest
import warnings

import test_recording as tr  # the recorded experiment of test_recording.py (module only)
from e2e_util import BIN_DIR

from convoy_mcap import McapError, McapIncompleteWarning, Recording  # noqa: E402 (tr set the path)

CONVOY_MCAP = os.path.join(BIN_DIR, "convoy-mcap")
MCAP_CHECK = os.path.join(tr.MCAP_CHECK, "check.mjs")


def node_missing():
    """Why @mcap/core cannot be run here, or None."""
    if not shutil.which("node"):
        return "node is not installed"
    if not os.path.isdir(os.path.join(tr.MCAP_CHECK, "node_modules", "@mcap", "core")):
        return "tools/mcap_check is not installed (scripts/setup.sh runs npm ci there)"
    return None


def python_read(path):
    """(messages as (topic, sequence, log_time, data), incomplete reason) or McapError."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        rec = Recording(path)
    msgs = [(m.topic, m.sequence, m.log_time, m.data) for m in rec.messages()]
    warned = [w for w in caught if issubclass(w.category, McapIncompleteWarning)]
    return rec, msgs, warned


def counts(msgs):
    out = {}
    for m in msgs:
        out[m[0]] = out.get(m[0], 0) + 1
    return out


class ReadersTestCase(tr.RecordingTestCase):
    @classmethod
    def setUpClass(cls):
        super().setUpClass()
        if not os.access(CONVOY_MCAP, os.X_OK):
            raise unittest.SkipTest("no %s (build the target convoy-mcap)" % CONVOY_MCAP)
        cls.node_why = node_missing()
        if cls.node_why:
            print("\n[@mcap/core part skipped: %s]" % cls.node_why)

    def cpp_read(self, path):
        """Convoy's C++ reader: (exit code, JSON or None, stderr)."""
        r = subprocess.run([CONVOY_MCAP, path], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                           text=True, timeout=60)
        self.assertGreaterEqual(r.returncode, 0, "convoy-mcap crashed on %s: %s" % (path, r.stderr))
        return r.returncode, (json.loads(r.stdout) if r.returncode == 0 else None), r.stderr

    def node_read(self, *paths):
        """@mcap/core's streaming reader: its JSON for each file, or None when not installed."""
        if self.node_why:
            return None
        r = subprocess.run(["node", MCAP_CHECK, "--partial"] + list(paths), stdout=subprocess.PIPE,
                           stderr=subprocess.PIPE, text=True, timeout=120)
        self.assertEqual(r.returncode, 0, "@mcap/core refused %s: %s %s" % (paths, r.stdout, r.stderr))
        out = [json.loads(line) for line in r.stdout.splitlines()]
        self.assertEqual([o["file"] for o in out], list(paths))
        return out

    def assertReadersAgree(self, path, msgs, node=True):
        """Convoy's C++ reader and @mcap/core (unless not `node`) see the messages the Python
        reader saw."""
        code, got, err = self.cpp_read(path)
        self.assertEqual(code, 0, err)
        self.assertEqual((got["messages"], got["topics"]), (len(msgs), counts(msgs)))
        if not got["complete"]:
            self.assertIn("warning: %s: incomplete recording" % path, err)
        if not node:
            return got, None
        node = self.node_read(path)
        if node is not None:
            node = node[0]
            self.assertEqual((node["messages"], node["topics"]), (len(msgs), counts(msgs)))
        return got, node


class KilledCoordinator(ReadersTestCase):
    def run_and_kill(self, after_s):
        """Runs without end and SIGKILLs the coordinator `after_s` after its recording got its
        first chunk. Returns the file's sizes seen while it ran: [(time, size)]."""
        self.write_config(tr.config(timeout=0))
        shutil.rmtree(self.run_dir, ignore_errors=True)
        p = self.start(["--record"])
        t0 = time.monotonic()
        sizes, first = [], None
        while time.monotonic() - t0 < 30:
            if p.poll() is not None:
                self.fail("the run ended by itself: %s" % self.finish(p))
            try:
                size = os.path.getsize(self.mcap)
            except OSError:
                size = -1
            now = time.monotonic()
            if not sizes or size != sizes[-1][1]:
                sizes.append((now, size))
            if first is None and size > 2000:  # header + metadata: about 1.5 kB
                first = now
            if first is not None and now - first >= after_s:
                break
            time.sleep(0.02)
        self.assertIsNotNone(first, "the recording got no chunk within 30 s")
        os.kill(p.pid, signal.SIGKILL)
        p.wait(timeout=10)
        self.assertEqual(p.returncode, -signal.SIGKILL)
        self.assertNoEngineLeft(within=5.0)
        return sizes

    def test_sigkill_at_several_points(self):
        found = []
        for after_s in (0.3, 2.0, 3.5):
            sizes = self.run_and_kill(after_s)
            size = os.path.getsize(self.mcap)
            rec, msgs, warned = python_read(self.mcap)
            self.assertFalse(rec.complete)
            self.assertEqual(len(warned), 1, "one McapIncompleteWarning, not %s" % warned)
            self.assertIn("incomplete recording", str(warned[0].message))
            # A prefix of the run, with no gap: the car's state every 10 ms from 0, the
            # world's speed every 20 ms, in order.
            states = [m for m in msgs if m[0] == "car/state"]
            self.assertGreater(len(states), 0)
            self.assertEqual([m[2] for m in states], [i * 10_000_000 for i in range(len(states))])
            speeds = [m[2] for m in msgs if m[0] == "world/speed"]
            self.assertEqual(speeds, [i * 20_000_000 for i in range(len(speeds))])
            self.assertIn("convoy", rec.metadata)  # written before the first chunk
            self.assertNotIn("convoy_end", rec.metadata)
            # What the disk had before the kill is all there: the kill lost the open chunk only.
            self.assertGreaterEqual(size, sizes[-1][1])
            # The file grew at least every ~1 s of the run (chunks close after 1 s of wall;
            # 1 MiB alone would take this run ~3 s a chunk).
            # (From the first chunk on: before it, the engines start.)
            growth = [b[0] - a[0] for a, b in zip(sizes[2:], sizes[3:])]
            cpp, node = self.assertReadersAgree(self.mcap, msgs)
            self.assertFalse(cpp["complete"])
            found.append((after_s, size, len(msgs), max(growth, default=0), rec.incomplete))
            print("\n[killed the coordinator %.1f s after its first chunk: %d bytes, %d messages "
                  "read by Python, C++%s; longest wait for a chunk %.2f s; %s]"
                  % (after_s, size, len(msgs), " and @mcap/core" if node else "",
                     max(growth, default=0), rec.incomplete))
            self.assertLess(max(growth, default=0), 2.0, sizes)
        # Later kills, more messages.
        self.assertEqual([f[2] for f in found], sorted(f[2] for f in found))
        self.assertLess(found[0][2], found[-1][2])


def chunk_table(path):
    """[(chunk end offset, messages in it)] of a finished recording, from its indexes."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", McapIncompleteWarning)
        rec = Recording(path)
    buf = rec.buf
    out = []
    for ci in rec.chunk_indexes:
        n = 0
        for moff in ci["index_offsets"].values():
            n += struct.unpack_from("<I", buf, moff + 9 + 2)[0] // 16
        out.append((ci["offset"] + ci["length"], n))
    return rec, out


class Truncated(ReadersTestCase):
    def test_cut_at_random_offsets(self):
        # With the blobs (a 40 kB frame every 20 ms): chunks fill by size, several of them
        # (1 simulated s: about 9; every cut file is read by all three readers, @mcap/core's
        # pure-JavaScript zstd taking the longest, so the recording is kept short).
        self.write_config(tr.config(timeout=1))
        self.assertExit(self.record("--record-blobs"), 0)
        full, table = chunk_table(self.mcap)
        all_msgs = [(m.topic, m.sequence, m.log_time, m.data) for m in full.messages()]
        size = len(full.buf)
        self.assertGreater(len(table), 1, "one chunk only: nothing to cut between")
        header_end = 8 + 9 + struct.unpack_from("<Q", full.buf, 9)[0]
        rnd = random.Random(30)
        cuts = {0, 5, 8, 12, header_end - 1, header_end, size - 1, size - 8}
        for end, _ in table[:3] + table[-2:]:
            cuts |= {end - 1, end, end + 1}
        cuts |= {rnd.randrange(size) for _ in range(16)}
        results, expected = [], {}
        for cut in sorted(cuts):
            cut_file = os.path.join(self.dir, "cut_%07d.mcap" % cut)
            with open(cut_file, "wb") as f:
                f.write(full.buf[:cut])
            whole = sum(n for end, n in table if end <= cut)
            if cut < header_end:  # no whole Header: not a recording; one clear error
                with self.assertRaises(McapError):
                    python_read(cut_file)
                code, _, err = self.cpp_read(cut_file)
                self.assertEqual(code, 2, err)
                self.assertEqual(err.count("error:"), 1, err)
                self.assertIn(cut_file, err)
                results.append((cut, "refused"))
                continue
            rec, msgs, warned = python_read(cut_file)
            self.assertEqual(len(warned), 0 if rec.complete else 1)
            # The messages of the whole chunks before the cut, exactly, as the full file has
            # them (cut after the last chunk: all of them).
            self.assertEqual(msgs, all_msgs[:len(msgs)])
            self.assertEqual(len(msgs), whole, "cut at byte %d of %d" % (cut, size))
            self.assertReadersAgree(cut_file, msgs, node=False)
            expected[cut_file] = (len(msgs), counts(msgs))
            results.append((cut, len(msgs)))
        # @mcap/core, all the cut files in one process.
        for got in self.node_read(*sorted(expected)) or []:
            self.assertEqual((got["messages"], got["topics"]), expected[got["file"]], got["file"])
        read = [r[1] for r in results if r[1] != "refused"]
        self.assertEqual(read, sorted(read))  # a longer prefix never reads fewer messages
        print("\n[%d cuts of a %d-byte recording (%d chunks, %d messages): %d refused (no whole "
              "Header), the others read %s messages; readers: Python, C++%s]"
              % (len(results), size, len(table), len(all_msgs),
                 len(results) - len(read), sorted(set(read)),
                 "" if self.node_why else ", @mcap/core"))


if __name__ == "__main__":
    unittest.main()
