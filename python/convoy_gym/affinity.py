"""Core pinning for VectorDrivingEnv: which cores each environment's processes may run on.

    sets = core_sets("auto", num_envs=2)   # [{0}, {1}] on 2 allowed cores; None when 1 env
    with pinned(sets[0]):
        env = DrivingEnv(...)              # NRPCoreSim and its engines start on core 0

pinned() sets the calling thread's CPU affinity (Linux: sched_setaffinity(0) is the calling
thread's) for the time of the block and restores it after: a process started in the block
(subprocess.Popen, from this thread) inherits the mask, and so do the processes it starts
(the server's engines), without a preexec_fn (unsafe with threads) or a `taskset` prefix.
Only the thread is pinned, not the rest of this process. See docs/gym.md, "Parallel
environments".
"""
import contextlib
import os

__all__ = ["core_sets", "pinned", "render_threads", "PINNED_RENDER_THREADS"]

# llvmpipe's rasteriser threads for a camera pinned to one core. Mesa sizes them to the cores
# the process may use: none on one core (the engine's thread rasterises). Measured on 2 cores
# (VectorDrivingEnv(2, camera=(84, 84)), pinned, in alternation): 2 threads 282-315 env
# steps/s at 5.4-5.7 ms of CPU a step, 1 thread 259-283, none 224-278 at 5.9-6.3 ms.
PINNED_RENDER_THREADS = "2"


def core_sets(cpu_affinity, num_envs, allowed=None):
    """num_envs frozensets of cores (or None: not pinned), one per environment.

    :param cpu_affinity: "auto" (one core each, round-robin over the allowed cores, when
        num_envs >= 2; else not pinned), True (one core each, also for one environment),
        None / False (never), or a list of num_envs entries, each a core (int), an iterable
        of cores or None
    :param allowed: the cores this process may use (default os.sched_getaffinity(0))
    Raises ValueError naming the value for anything else, or a core not allowed."""
    allowed = sorted(os.sched_getaffinity(0) if allowed is None else allowed)
    if cpu_affinity is None or cpu_affinity is False:
        return [None] * num_envs
    if cpu_affinity is True or (isinstance(cpu_affinity, str) and cpu_affinity == "auto"):
        if cpu_affinity == "auto" and num_envs < 2:
            return [None] * num_envs
        return [frozenset([allowed[i % len(allowed)]]) for i in range(num_envs)]
    if isinstance(cpu_affinity, (str, bytes, int, float)) or \
            not hasattr(cpu_affinity, "__len__"):
        raise ValueError("cpu_affinity must be \"auto\", True, None, False or a list of %d core "
                         "sets, got %r" % (num_envs, cpu_affinity))
    if len(cpu_affinity) != num_envs:
        raise ValueError("cpu_affinity: %d core sets for %d envs, got %r"
                         % (len(cpu_affinity), num_envs, cpu_affinity))
    return [_core_set(entry, i, allowed) for i, entry in enumerate(cpu_affinity)]


def _core_set(entry, index, allowed):
    if entry is None:
        return None
    cores = [entry] if _is_int(entry) else entry
    try:
        cores = list(cores)
    except TypeError:
        raise ValueError("cpu_affinity[%d]: %r is not a core or a set of cores"
                         % (index, entry)) from None
    if not cores or not all(_is_int(c) for c in cores):
        raise ValueError("cpu_affinity[%d]: %r is not a core or a non-empty set of cores"
                         % (index, entry))
    outside = sorted(int(c) for c in cores if int(c) not in allowed)
    if outside:
        raise ValueError("cpu_affinity[%d]: core(s) %s not among this process' allowed cores "
                         "%s (os.sched_getaffinity(0)), got %r"
                         % (index, ",".join(map(str, outside)), allowed, entry))
    return frozenset(int(c) for c in cores)


def _is_int(value):
    return hasattr(value, "__index__") and not isinstance(value, bool)


@contextlib.contextmanager
def render_threads(needed):
    """Inside the block, LP_NUM_THREADS=PINNED_RENDER_THREADS in this process' environment
    (the servers started in it inherit it) if `needed` and LP_NUM_THREADS is not set."""
    if not needed or "LP_NUM_THREADS" in os.environ:
        yield
        return
    os.environ["LP_NUM_THREADS"] = PINNED_RENDER_THREADS
    try:
        yield
    finally:
        os.environ.pop("LP_NUM_THREADS", None)


@contextlib.contextmanager
def pinned(cores):
    """The calling thread runs on `cores` (a set; None: unchanged) inside the block; the
    processes it starts there keep that mask."""
    if cores is None:
        yield
        return
    before = os.sched_getaffinity(0)
    os.sched_setaffinity(0, cores)
    try:
        yield
    finally:
        os.sched_setaffinity(0, before)
