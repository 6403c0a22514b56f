"""The experiments' video writer: camera frames to an H.264 `.mp4` that browsers play
(docs/architecture.md, "Video").

    from convoy_video import VideoWriter
    video = VideoWriter(os.path.join(run_dir, "camera.mp4"), fps=30)
    video.write(bgr_frame)      # HxWx3 uint8, BGR as OpenCV draws it; the size of the first
    ...                         # frame is the video's
    video.close()               # also at interpreter exit

Frames go through a pipe to a separate `ffmpeg` process (libx264, yuv420p, a fragmented MP4:
`-movflags +frag_keyframe+empty_moov+default_base_moof`), which encodes on the other core while
the engine steps; `write` only copies the
frame into the pipe, and blocks when the encoder is behind, so no frame is dropped and the
simulation never sees the encoder (its results do not depend on it).

Failures:
- no `ffmpeg` with libx264 on PATH: one warning line, then OpenCV's MPEG-4 part 2 (`mp4v`)
  in the engine's thread, as before;
- `ffmpeg` dies: one line with its exit status; later frames are counted as lost, and the run
  goes on;
- the engine dies (a crash, SIGKILL): `ffmpeg` runs in its own session, so the clean-up of the
  engine's process group does not cut it off; the pipe's end reaches it as end of input and it
  finishes the file (a playable video of the frames written so far) and exits.
"""
import atexit
import os
import shutil
import signal
import subprocess
import sys

PRESET = "veryfast"
CRF = 23
# One encoder thread: the co-simulation's engines keep the cores busy, and x264's frame threads
# cost 18 % more CPU for the same video (a 736x480 camera: 4.0 -> 3.3 s for 750 frames).
THREADS = 1
_F_SETPIPE_SZ = 1031  # fcntl.F_SETPIPE_SZ (Linux), not in Python 3.11's fcntl


def _log(text):
    print("video: " + text, file=sys.stdout, flush=True)


def ffmpeg_h264():
    """The path of an `ffmpeg` that has the libx264 encoder, or None."""
    exe = os.environ.get("CONVOY_FFMPEG") or shutil.which("ffmpeg")
    if not exe:
        return None
    try:
        out = subprocess.run([exe, "-hide_banner", "-h", "encoder=libx264"], capture_output=True,
                             text=True, timeout=20)
    except (OSError, subprocess.SubprocessError):
        return None
    return exe if out.returncode == 0 and "libx264" in out.stdout else None


class VideoWriter:
    def __init__(self, path, fps):
        self.path = path
        self.fps = fps
        self.frames = 0      # frames written to the encoder
        self.lost = 0        # frames after the encoder failed
        self.codec = None    # "h264" or "mpeg4", once the first frame has come
        self.size = None     # (width, height)
        self._proc = None
        self._pipe = None
        self._cv = None
        self._closed = False
        atexit.register(self.close)

    # -- opening, at the first frame ---------------------------------------------------------

    def _open(self, width, height):
        self.size = (width, height)
        exe = ffmpeg_h264()
        if exe is None:
            self._open_cv(width, height)
            _log("warning: no ffmpeg with libx264 on PATH (Debian: apt-get install ffmpeg); "
                 "writing %s as MPEG-4 part 2 (mp4v)" % self.path)
            return
        cmd = [exe, "-hide_banner", "-nostats", "-loglevel", "error", "-y",
               "-f", "rawvideo", "-pix_fmt", "bgr24", "-s", "%dx%d" % (width, height),
               "-framerate", str(self.fps), "-i", "pipe:0", "-an"]
        if width % 2 or height % 2:  # yuv420p halves both: pad to even sizes
            cmd += ["-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2"]
        cmd += ["-c:v", "libx264", "-preset", PRESET, "-crf", str(CRF), "-threads", str(THREADS),
                "-pix_fmt", "yuv420p",
                # Fragmented (a fragment per key frame, 250 frames): the muxer keeps no index of
                # the whole video (an hour's grew ffmpeg by 12 MiB, and +faststart rewrote the
                # file at the end), browsers stream it (the moov box comes first), and a
                # file cut short plays up to its last fragment.
                "-movflags", "+frag_keyframe+empty_moov+default_base_moof",
                "-fflags", "+bitexact", "-flags:v", "+bitexact",
                self.path]
        # A broken pipe is an error to report, not a signal that ends the engine (the embedded
        # interpreter leaves SIGPIPE at its default). The main thread only may set it.
        try:
            signal.signal(signal.SIGPIPE, signal.SIG_IGN)
        except (ValueError, OSError):
            pass
        self._proc = subprocess.Popen(cmd, stdin=subprocess.PIPE, stdout=subprocess.DEVNULL,
                                      start_new_session=True)
        self._pipe = self._proc.stdin
        try:  # one frame in flight: the encoder's reads then rarely make a write wait
            import fcntl
            fcntl.fcntl(self._pipe.fileno(), _F_SETPIPE_SZ, 1 << 20)
        except OSError:
            pass
        self.codec = "h264"

    def _open_cv(self, width, height):
        import cv2
        self._cv = cv2.VideoWriter(self.path, cv2.VideoWriter_fourcc(*"mp4v"), self.fps,
                                   (width, height))
        self.codec = "mpeg4"

    # -- writing -----------------------------------------------------------------------------

    def write(self, frame):
        """Appends one HxWx3 uint8 BGR frame."""
        if self._closed:
            raise ValueError("%s: write after close" % self.path)
        h, w = frame.shape[:2]
        if self.size is None:
            self._open(w, h)
        elif (w, h) != self.size:
            raise ValueError("%s: frame of %dx%d in a %dx%d video" % (self.path, w, h, *self.size))
        if self._cv is not None:
            self._cv.write(frame)
            self.frames += 1
            return
        if self._pipe is None:  # the encoder failed
            self.lost += 1
            return
        if not frame.flags.c_contiguous:
            import numpy as np
            frame = np.ascontiguousarray(frame)
        try:
            self._pipe.write(memoryview(frame).cast("B"))
            self.frames += 1
        except (BrokenPipeError, OSError) as e:
            self.lost += 1
            self._pipe = None
            code = self._proc.wait()
            _log("error: ffmpeg stopped (exit status %s: %s) after %d frames; %s keeps what it "
                 "finished, the rest of the run is not recorded" % (code, e, self.frames, self.path))

    # -- closing -----------------------------------------------------------------------------

    def close(self, timeout_s=300.0):
        """Finishes the file (waits for the encoder). Returns True if the video is complete."""
        if self._closed:
            return self.lost == 0
        self._closed = True
        if self._cv is not None:
            self._cv.release()
            return True
        if self._proc is None:
            return True
        if self._pipe is not None:
            try:
                self._pipe.close()
            except OSError:
                pass
        else:  # it failed while writing: already reported
            try:
                self._proc.stdin.close()
            except OSError:
                pass
        try:
            code = self._proc.wait(timeout=timeout_s)
        except subprocess.TimeoutExpired:
            self._proc.kill()
            code = self._proc.wait()
            _log("error: ffmpeg did not finish %s within %.0f s: killed" % (self.path, timeout_s))
            return False
        if code != 0 and self._pipe is not None:
            _log("error: ffmpeg exited with status %d writing %s" % (code, self.path))
        return code == 0 and self.lost == 0
