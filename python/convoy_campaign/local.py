"""The local backend: the campaign's tasks on this machine, `workers` at a time.

Each task not yet done (state "pending", "queued", "running" or "failed": a task that failed in
an earlier invocation with the same --out runs again) runs through worker.run_task in a pool of
`workers` threads, each waiting on its own `convoy run` process; so at most `workers` runs at
once. Tasks start in index order. campaign.json is saved as each task starts and ends. A
failed task is not retried within the invocation.
"""

import threading
from concurrent.futures import ThreadPoolExecutor

from . import worker


def run(plan, state, workers, log=print):
    lock = threading.Lock()
    todo = [t["index"] for t in state.tasks if t["state"] != "done"]

    def one(index):
        with lock:
            t = state.tasks[index]
            t["attempts"] += 1
            t["state"] = "running"
            t["job_id"] = "local"
            state.save()
        record = worker.run_task(plan, index, job_id="local")
        with lock:
            state.finish(index, record["exit_code"], record["wall_s"])
            state.save()
            log("campaign: %s: exit %d, %.1f s" % (record["name"], record["exit_code"],
                                                   record["wall_s"]))

    with ThreadPoolExecutor(max_workers=workers) as pool:
        for f in [pool.submit(one, i) for i in todo]:
            f.result()
