"""traffic_bench.py's `pooled` section: road_user_pool vehicles at 20 Hz on a generated 10x10
grid (netgenerate, then netconvert to OpenDRIVE), the pool's step alone (traffic_pool_bench)
and inside the coordinator loop; its last line is `pooled road users at real time: N`.
Run it through traffic_bench.py (`--sections pooled`), which documents the options."""
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import textwrap

SUMO_HOME = os.environ.get("SUMO_HOME", "/usr/share/sumo")


def run(cmd, **kw):
    """The command's CompletedProcess; a failure ends the benchmark with its output."""
    r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, **kw)
    if r.returncode != 0:
        sys.exit("failed: %s\n%s\n%s" % (" ".join(cmd), r.stdout[-2000:], r.stderr[-2000:]))
    return r


POOL_TF = textwrap.dedent("""\
    from nrp_core import *


    @EngineDataPack(keyword="v", id=DataPackIdentifier("road_users", "pool"))
    @TransceiverFunction("pool")
    def read_pool(v):
        if not v.isEmpty():
            len(v.data.users)
        return []
    """)


def make_pool_grid(work, length):
    env = dict(os.environ, SUMO_HOME=SUMO_HOME)
    net = os.path.join(work, "pool_grid.net.xml")
    xodr = os.path.join(work, "pool_grid.xodr")
    run(["netgenerate", "--grid", "--grid.number=10", "--grid.length=%g" % length,
         "--default.lanenumber", "2", "--tls.guess", "true", "-o", net], env=env)
    run(["netconvert", "-s", net, "--opendrive-output", xodr], env=env)
    return xodr


def pooled_loop_run(work, xodr, n, end, i, build):
    exp = os.path.join(work, "pool%d_%d" % (n, i))
    os.makedirs(exp)
    with open(os.path.join(exp, "tf.py"), "w") as f:
        f.write(POOL_TF)
    with open(os.path.join(exp, "simulation_config.json"), "w") as f:
        json.dump({"SimulationName": "traffic_bench_pooled", "SimulationTimeout": end,
                   "EngineConfigs": [{"EngineType": "road_user_pool", "EngineName": "pool",
                                      "EngineTimestep": 0.05, "Map": xodr, "Count": n,
                                      "Seed": 1}],
                   "DataPackProcessingFunctions": [{"Name": "read_pool", "FileName": "tf.py"}]},
                  f)
    run_dir = os.path.join(exp, "run")
    run([os.path.join(build, "bin", "convoy"), "run", "-q", "-c",
         os.path.join(exp, "simulation_config.json"), "--run-dir", run_dir])
    with open(os.path.join(run_dir, "summary.json")) as f:
        summary = json.load(f)
    shutil.rmtree(exp, ignore_errors=True)
    return summary["real_time_factor"]


def section_pooled(args):
    bench = os.path.join(args.build, "benchmarks", "traffic_pool_bench")
    if not os.path.exists(os.path.join(args.build, "bin", "convoy-engine-road_user_pool")) \
            or not os.path.exists(bench):
        print("pooled: convoy-engine-road_user_pool or traffic_pool_bench is not built")
        return
    work = tempfile.mkdtemp(prefix="convoy-trafficbench-pooled-")
    best = 0
    try:
        xodr = make_pool_grid(work, args.pool_grid_length)
        print("pooled: road_user_pool, 10x10 grid x %g m, 2 lanes a direction, lights where "
              "netgenerate guessed them, 20 Hz, %g s simulated, %d run(s) in the loop"
              % (args.pool_grid_length, args.pool_end, args.runs), flush=True)
        alone = run([bench, xodr, "--counts", args.pooled, "--seconds", str(args.pool_end)])
        print("  the pool's step alone (traffic_pool_bench):")
        for line in alone.stdout.splitlines():
            print("    " + line.strip())
        if args.pool_collision_count > 0:
            col = run([bench, xodr, "--counts", str(args.pool_collision_count),
                       "--seconds", "600"])
            print("  collisions, %d vehicles for 600 simulated s:" % args.pool_collision_count)
            for line in col.stdout.splitlines()[1:-1]:
                print("    " + line.strip())
        print("  inside the coordinator loop (engine + a TF reading every vehicle each step):")
        for n in [int(x) for x in args.pooled.split(",")]:
            rtfs = [pooled_loop_run(work, xodr, n, args.pool_end, i, args.build)
                    for i in range(args.runs)]
            rtf = statistics.median(rtfs)
            print("    N = %6d: real-time factor %.2fx (runs: %s)"
                  % (n, rtf, ", ".join("%.2f" % r for r in rtfs)), flush=True)
            if rtf >= 1.0:
                best = max(best, n)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    print("pooled road users at real time: %d" % best)


