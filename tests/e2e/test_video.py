"""convoy_video.VideoWriter: H.264 in an .mp4 through ffmpeg (codec, frame count, pixel
format, moov first), the mp4v fallback without ffmpeg, a failing ffmpeg, odd frame sizes, and
a writer killed midway (the video of what was written stays playable). Also a short Parkring
run: its camera.mp4 is H.264 and summary.json has the start-up figures."""
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import textwrap
import time
import unittest

import numpy as np

from e2e_util import BIN_DIR, REPO

sys.path.insert(0, os.path.join(REPO, "python"))
from convoy_video import VideoWriter  # noqa: E402

PY = "/usr/bin/python3"
HAVE_FFMPEG = shutil.which("ffmpeg") is not None and shutil.which("ffprobe") is not None


def probe(path):
    """(codec, frames, pix_fmt, width, height) of the video stream, counted by decoding."""
    r = subprocess.run(["ffprobe", "-v", "error", "-count_frames", "-select_streams", "v:0",
                        "-show_entries", "stream=codec_name,nb_read_frames,pix_fmt,width,height",
                        "-of", "json", path], capture_output=True, text=True, timeout=60)
    if r.returncode != 0:
        raise AssertionError("ffprobe %s: %s" % (path, r.stderr))
    s = json.loads(r.stdout)["streams"][0]
    return s["codec_name"], int(s["nb_read_frames"]), s.get("pix_fmt"), s["width"], s["height"]


def frames(n, w=160, h=120):
    """Distinct frames: a moving bar on a gradient."""
    out = []
    for i in range(n):
        f = np.zeros((h, w, 3), np.uint8)
        f[:, :, 0] = np.linspace(0, 255, w, dtype=np.uint8)[None, :]
        f[:, (i * 3) % w:(i * 3) % w + 8, 1] = 255
        out.append(f)
    return out


@unittest.skipUnless(HAVE_FFMPEG, "needs ffmpeg and ffprobe (Debian: apt-get install ffmpeg)")
class Writer(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.mkdtemp(prefix="convoy-video-")
        self.addCleanup(shutil.rmtree, self.dir, True)

    def test_h264_with_every_frame_for_browsers(self):
        path = os.path.join(self.dir, "camera.mp4")
        v = VideoWriter(path, 30)
        for f in frames(45):
            v.write(f)
        self.assertTrue(v.close())
        self.assertEqual(v.codec, "h264")
        self.assertEqual(probe(path), ("h264", 45, "yuv420p", 160, 120))
        with open(path, "rb") as f:
            head = f.read(64)
        self.assertLess(head.find(b"moov"), head.find(b"mdat") if b"mdat" in head else 1 << 30,
                        "moov is not before mdat (browsers stream it)")
        self.assertIn(b"moov", head)
        with open(path, "rb") as f:
            self.assertIn(b"moof", f.read(), "not fragmented (an index of the whole video in memory)")

    def test_odd_sizes_are_padded_to_even(self):
        path = os.path.join(self.dir, "odd.mp4")
        v = VideoWriter(path, 15)
        for f in frames(10, w=161, h=99):
            v.write(f)
        self.assertTrue(v.close())
        self.assertEqual(probe(path), ("h264", 10, "yuv420p", 162, 100))

    def test_a_frame_of_another_size_is_an_error_naming_both(self):
        v = VideoWriter(os.path.join(self.dir, "x.mp4"), 30)
        v.write(frames(1)[0])
        with self.assertRaisesRegex(ValueError, "frame of 80x60 in a 160x120 video"):
            v.write(frames(1, 80, 60)[0])
        v.close()

    def test_without_ffmpeg_it_writes_mp4v_with_one_warning(self):
        path = os.path.join(self.dir, "fallback.mp4")
        code = textwrap.dedent("""
            import sys; sys.path.insert(0, %r); sys.path.insert(0, %r)
            from convoy_video import VideoWriter
            from test_video import frames
            v = VideoWriter(%r, 30)
            for f in frames(12):
                v.write(f)
            v.close()
            print("codec", v.codec, v.frames)
        """ % (os.path.join(REPO, "python"), os.path.dirname(os.path.abspath(__file__)), path))
        env = dict(os.environ, PATH="/nonexistent")
        env.pop("CONVOY_FFMPEG", None)
        r = subprocess.run([PY, "-c", code], capture_output=True, text=True, env=env, timeout=60)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(r.stdout.count("warning"), 1, r.stdout)
        self.assertIn("no ffmpeg with libx264", r.stdout)
        self.assertIn("codec mpeg4 12", r.stdout)
        self.assertEqual(probe(path)[:2], ("mpeg4", 12))

    def test_an_ffmpeg_that_dies_is_reported_once_and_the_writer_goes_on(self):
        fake = os.path.join(self.dir, "ffmpeg")
        real = shutil.which("ffmpeg")
        # answers the encoder check like the real one, then fails at once
        with open(fake, "w") as f:
            f.write("#!/bin/sh\ncase \"$*\" in *encoder=libx264*) exec %s \"$@\";; esac\n"
                    "echo 'fake ffmpeg: no space left' >&2; exit 3\n" % real)
        os.chmod(fake, 0o755)
        code = textwrap.dedent("""
            import sys; sys.path.insert(0, %r); sys.path.insert(0, %r)
            from convoy_video import VideoWriter
            from test_video import frames
            v = VideoWriter(%r, 30)
            for f in frames(40, 640, 480):
                v.write(f)
            print("complete", v.close(), "written", v.frames, "lost", v.lost)
        """ % (os.path.join(REPO, "python"), os.path.dirname(os.path.abspath(__file__)),
               os.path.join(self.dir, "dies.mp4")))
        r = subprocess.run([PY, "-c", code], capture_output=True, text=True, timeout=60,
                           env=dict(os.environ, CONVOY_FFMPEG=fake))
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("complete False", r.stdout)
        self.assertEqual(r.stdout.count("video: error: ffmpeg stopped (exit status 3"), 1, r.stdout)
        self.assertIn("fake ffmpeg: no space left", r.stderr)

    def test_a_writer_killed_midway_leaves_a_playable_video(self):
        path = os.path.join(self.dir, "killed.mp4")
        code = textwrap.dedent("""
            import os, signal, sys; sys.path.insert(0, %r); sys.path.insert(0, %r)
            from convoy_video import VideoWriter
            from test_video import frames
            v = VideoWriter(%r, 30)
            for f in frames(60):
                v.write(f)
            os.killpg(0, signal.SIGKILL)  # as the coordinator ends an engine's process group
        """ % (os.path.join(REPO, "python"), os.path.dirname(os.path.abspath(__file__)), path))
        r = subprocess.run([PY, "-c", code], capture_output=True, text=True, timeout=60,
                           start_new_session=True)
        self.assertEqual(r.returncode, -signal.SIGKILL)
        # ffmpeg, in a session of its own, sees the end of its input and finishes the file
        deadline = time.monotonic() + 20
        while True:
            try:
                self.assertEqual(probe(path)[:2], ("h264", 60))
                break
            except AssertionError:
                if time.monotonic() > deadline:
                    raise
                time.sleep(0.2)


@unittest.skipUnless(HAVE_FFMPEG, "needs ffmpeg and ffprobe (Debian: apt-get install ffmpeg)")
class Parkring(unittest.TestCase):
    def test_camera_is_h264_and_summary_has_the_start_up(self):
        d = tempfile.mkdtemp(prefix="convoy-video-run-")
        self.addCleanup(shutil.rmtree, d, True)
        cfg = os.path.join(REPO, "experiments", "autonomous_driving", "simulation_config_both.json")
        r = subprocess.run([os.path.join(BIN_DIR, "convoy"), "run", "-q", "-c", cfg, "-o",
                            "SimulationTimeout=2", "--run-dir", d], capture_output=True, text=True,
                           timeout=300)
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(os.path.join(d, "summary.json")) as f:
            s = json.load(f)
        codec, n, pix, w, h = probe(os.path.join(d, "camera.mp4"))
        self.assertEqual((codec, pix, w, h), ("h264", "yuv420p", 736, 480))
        self.assertEqual(n, s["camera_frames"])
        self.assertGreater(n, 50)
        self.assertEqual(s["camera_video_codec"], "h264")
        # start-up: the command's start to the first loop step, and its parts
        self.assertGreater(s["startup_s"], 0)
        self.assertLess(s["startup_s"], s["wall_s"] + 0.5)
        st = s["startup"]
        self.assertEqual(set(st["engines"]), {"gazebo", "weather", "car_ctl_engine", "yolo_detector",
                                              "evaluator"})
        for e in st["engines"].values():
            self.assertGreaterEqual(e["initialize_s"], 0)
            self.assertGreater(e["process_s"], 0)
        parts = sum(st[k] for k in ("process_s", "functions_s", "launch_s", "initialize_s", "prime_s"))
        self.assertAlmostEqual(parts, s["startup_s"], delta=0.05)


if __name__ == "__main__":
    unittest.main()
