"""Files a stopped campaign can trust, and the locks that keep two processes off the same files.

write_text / write_json: the whole file or nothing. The text goes to a temporary file in the
same folder (`.<name>.<pid>.tmp`), is flushed and fsync'ed, renamed over the target, and the
folder is fsync'ed; so a campaign killed (or a machine that stops) while writing leaves the old
file or the new one, never half of one. A temporary file left by a killed writer is harmless
and replaced by the next write.

Locks (flock on a file; released by the kernel when the last process holding it ends):
- try_lock(path): the campaign's own lock, OUT/campaign.lock, holding the pid of the campaign
  process that runs in that folder; a second campaign on the same --out is refused.
- wait_lock(path, timeout_s): a task's lock, OUT/locks/<task>.lock, which the worker passes on
  to the task's `convoy run`: a run orphaned by a killed campaign keeps it until it has ended,
  and the next attempt of that task waits for it before it touches the run folder.
"""

import fcntl
import json
import os
import time


def fsync_dir(path):
    try:
        fd = os.open(path, os.O_RDONLY | os.O_DIRECTORY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


def write_text(path, text):
    folder = os.path.dirname(os.path.abspath(path))
    tmp = os.path.join(folder, ".%s.%d.tmp" % (os.path.basename(path), os.getpid()))
    try:
        with open(tmp, "w", newline="") as f:
            f.write(text)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        raise
    fsync_dir(folder)
    return path


def write_json(path, doc, **dump_args):
    return write_text(path, json.dumps(doc, **dump_args) + "\n")


class Busy(Exception):
    """The lock is held by another process; args[0] is what its file says (a pid or '')."""


def _open_lock(path):
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    return os.open(path, os.O_RDWR | os.O_CREAT | os.O_CLOEXEC, 0o644)


def _holder(fd):
    try:
        return os.pread(fd, 64, 0).decode(errors="replace").strip()
    except OSError:
        return ""


def try_lock(path):
    """The fd of `path` locked (our pid written into it), or Busy(holder's pid)."""
    fd = _open_lock(path)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        holder = _holder(fd)
        os.close(fd)
        raise Busy(holder) from None
    os.ftruncate(fd, 0)
    os.pwrite(fd, b"%d\n" % os.getpid(), 0)
    return fd


def wait_lock(path, timeout_s, on_wait=None, poll_s=0.1):
    """The fd of `path` locked, waiting up to timeout_s (on_wait() called once if it has to
    wait); Busy when it is still held then."""
    fd = _open_lock(path)
    deadline = time.monotonic() + timeout_s
    told = False
    while True:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            return fd
        except BlockingIOError:
            if time.monotonic() >= deadline:
                os.close(fd)
                raise Busy("") from None
            if not told and on_wait is not None:
                on_wait()
                told = True
            time.sleep(poll_s)
