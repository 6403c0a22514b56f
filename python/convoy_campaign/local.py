"""The local backend: the campaign's tasks on this machine, `workers` at a time.

Each task not yet done (state "pending", "queued", "running" or "failed": a task that failed in
an earlier invocation with the same --out runs again) runs through worker.run_task in a pool of
`workers` threads, each waiting on its own `convoy run` process; so at most `workers` runs at
once. Tasks start in index order. campaign.json is saved as each task starts and ends. A
failed task is not retried within the invocation.

Restart after the campaign was killed (SIGKILL, a lost machine): a task left "running" whose
run folder has the task.json of that attempt ended before the campaign stopped and is taken as
it is (state.adopt_finished); any other is run again from an empty run folder (its partial one
moved to OUT/previous/). Its `convoy run`, orphaned by the kill, got SIGTERM from the kernel
(the worker's parent-death signal) and still holds the task's lock until it has ended; the new
attempt waits for that (worker.py).

Interrupted (Ctrl-C, or SIGTERM to the campaign alone), it starts no more tasks, passes the
signal on to the runs in flight (each ends as `convoy run` does on Ctrl-C, its run folder
kept), waits for them, and re-raises KeyboardInterrupt: the tasks not run stay pending for the
next invocation.
"""

import signal
import threading
from concurrent.futures import ThreadPoolExecutor

from . import worker


def _raise_interrupt(signum, _frame):
    raise KeyboardInterrupt("signal %d" % signum)


def run(plan, state, workers, log=print):
    lock = threading.Lock()
    stop = threading.Event()
    state.adopt_finished(plan, log=log)
    state.save()
    todo = [t["index"] for t in state.tasks if t["state"] != "done"]

    def one(index):
        with lock:
            if stop.is_set():
                return
            t = state.tasks[index]
            t["attempts"] += 1
            t["state"] = "running"
            t["job_id"] = "local"
            attempt = t["attempts"]
            state.save()
        record = worker.run_task(plan, index, job_id="local", attempt=attempt)
        with lock:
            state.finish(index, record["exit_code"], record["wall_s"])
            state.save()
            log("campaign: %s: exit %d, %.1f s" % (record["name"], record["exit_code"],
                                                   record["wall_s"]))

    old_term = None
    if threading.current_thread() is threading.main_thread():
        old_term = signal.signal(signal.SIGTERM, _raise_interrupt)
    pool = ThreadPoolExecutor(max_workers=workers)
    futures = [pool.submit(one, i) for i in todo]
    try:
        for f in futures:
            f.result()
    except KeyboardInterrupt:
        with lock:
            stop.set()
        worker.interrupt_all(signal.SIGINT)
        pool.shutdown(wait=True, cancel_futures=True)
        raise
    finally:
        if old_term is not None:
            signal.signal(signal.SIGTERM, old_term)
    pool.shutdown(wait=True)
