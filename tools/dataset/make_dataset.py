#!/usr/bin/python3
"""Labelled data from any experiment: runs it --runs times, each with its own seed and (with
--randomize) its own weather and time of day, and writes every --every-th frame of one camera
with COCO ground truth (boxes, classes, instance ids, instance masks as RLE) and depth.

  /usr/bin/python3 tools/dataset/make_dataset.py CONFIG --out DIR [--runs 4] [--seed 0]
      [--every 15] [--seconds 60] [--camera smart_camera::camera] [--world gazebo]
      [--randomize | --weather KIND[,KIND...]] [--vary-models car=0.6,bus=0.2,truck=0.2]
      [--build build]

Writes DIR/annotations.json (all runs, COCO; each image's record has its seed, weather and
time), DIR/images/*.jpg, DIR/depth/*.png (mm, uint16), DIR/runs.json (what each run drew).
The experiment needs a world engine with the camera and a `weather` engine (every driving
experiment has one). What it adds to the run: the dataset_writer engine and its TF
(tools/dataset/). What it takes away: an engine named `recorder` (the run's video) steps only
once, at the start (the dataset has the frames; about a quarter of a core's time in ffmpeg).
docs/perception.md has the details.
"""
import argparse
import json
import os
import random
import shutil
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(REPO, "python"))


KINDS = ["clear", "rain", "fog", "snow", "dusk", "night"]


def draw_weather(rng, kind=None):
    """A weather for one run: clear most often, then rain, fog, snow, dusk and night; with
    `kind`, that kind's parameters (still drawn from rng)."""
    if kind is None:
        kind = rng.choices(KINDS, weights=[0.4, 0.15, 0.15, 0.1, 0.1, 0.1])[0]
    elif kind not in KINDS:
        raise ValueError("unknown weather kind '%s' (%s)" % (kind, ", ".join(KINDS)))
    w = {"TimeOfDay": round(rng.uniform(8.0, 16.5), 2)}
    if kind == "rain":
        w.update(Precipitation=round(rng.uniform(0.3, 1.0), 2), Surface="wet")
    elif kind == "fog":
        w.update(Visibility=round(rng.uniform(60, 400), 1))
    elif kind == "snow":
        w.update(Precipitation=round(rng.uniform(0.2, 0.8), 2), PrecipitationType="snow",
                 Surface="snow")
    elif kind == "dusk":
        w.update(TimeOfDay=round(rng.uniform(17.3, 18.3), 2))
    elif kind == "night":
        w.update(TimeOfDay=round(rng.uniform(19.0, 23.5), 2))
    return kind, w


def actor_table():
    """The world engine's actor table (engines/gazebo_grpc/actors/actor_models.json): model ->
    {"class", "size": [length, width, height], "length_offset", ...}."""
    with open(os.path.join(REPO, "engines", "gazebo_grpc", "actors", "actor_models.json")) as f:
        return json.load(f)["models"]


def actor_models():
    """The actor table's model names by class ({"car": [...], "bus": [...], ...})."""
    by_class = {}
    for name, entry in sorted(actor_table().items()):
        by_class.setdefault(entry["class"], []).append(name)
    return by_class


def vary_models(cfg, seed, shares):
    """Gives each vehicle_agent of cfg a model drawn for this run: a class by `shares`
    ({"car": 0.6, "bus": 0.2, "truck": 0.2}), then one of its variants; the agent takes the
    model's class as its Category and its size (Length, Width, Height, and a Wheelbase of twice
    the model's length_offset: the reference point is the rear axle). Its own random stream, so
    that the weather drawn does not change it. Returns {engine: model}."""
    rng = random.Random(seed * 7919 + 17)
    table = actor_table()
    by_class = actor_models()
    classes = sorted(shares)
    drawn = {}
    for e in cfg["EngineConfigs"]:
        if e.get("EngineType") == "vehicle_agent":
            cls = rng.choices(classes, weights=[shares[c] for c in classes])[0]
            model = drawn[e["EngineName"]] = rng.choice(by_class[cls])
            entry = table[model]
            length, width, height = entry["size"]
            e.update(Model=model, Category=entry["class"], Length=length, Width=width, Height=height,
                     Wheelbase=round(2 * entry["length_offset"], 3))
    return drawn


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("config")
    ap.add_argument("--out", required=True)
    ap.add_argument("--runs", type=int, default=4)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--every", type=int, default=15, help="keep every n-th new camera frame")
    ap.add_argument("--seconds", type=float, default=60.0, help="simulated seconds per run")
    ap.add_argument("--camera", default="smart_camera::camera")
    ap.add_argument("--world", default="gazebo", help="the world engine's name")
    ap.add_argument("--randomize", action="store_true", help="draw weather and time of day per run")
    ap.add_argument("--weather", metavar="KIND[,KIND...]",
                    help="the weather kind of each run, taken in turn (%s, or all); its parameters are "
                         "drawn from the run's seed" % ", ".join(KINDS))
    ap.add_argument("--vary-models", metavar="CLASS=SHARE[,...]",
                    help="give each vehicle_agent a model drawn per run: a class by these shares "
                         "(e.g. car=0.6,bus=0.2,truck=0.2), then one of its colour variants")
    ap.add_argument("--set", action="append", default=[], metavar="ENGINE.KEY=JSON",
                    help="set an engine's config key (the value read as JSON, else as a string)")
    ap.add_argument("--env", action="append", default=[], metavar="ENGINE:VAR=VALUE",
                    help="add an environment variable to an engine's EngineEnvParams")
    ap.add_argument("--build", default=os.path.join(REPO, "build"))
    args = ap.parse_args()

    kinds = None
    if args.weather:
        kinds = KINDS if args.weather == "all" else args.weather.split(",")
        bad = [k for k in kinds if k not in KINDS]
        if bad or args.randomize:
            sys.exit("make_dataset: --weather %s: %s" % (
                args.weather, "use either --weather or --randomize" if not bad else
                "unknown kind '%s' (%s, or all)" % (bad[0], ", ".join(KINDS))))
    shares = None
    if args.vary_models:
        try:
            shares = {k: float(v) for k, v in (item.split("=") for item in args.vary_models.split(","))}
        except ValueError:
            sys.exit("make_dataset: --vary-models %s: expected CLASS=SHARE[,CLASS=SHARE...]" % args.vary_models)
        known = actor_models()
        bad = [c for c in shares if c not in known or shares[c] < 0]
        if bad or sum(shares.values()) <= 0:
            sys.exit("make_dataset: --vary-models %s: %s" % (
                args.vary_models, "unknown class '%s' (%s)" % (bad[0], ", ".join(sorted(known))) if bad
                else "the shares add up to 0"))
    config_path = os.path.abspath(args.config)
    with open(config_path) as f:
        base = json.load(f)
    names = [e["EngineName"] for e in base["EngineConfigs"]]
    for needed in (args.world, "weather"):
        if needed not in names:
            sys.exit("make_dataset: %s has no engine '%s'" % (config_path, needed))
    world = base["EngineConfigs"][names.index(args.world)]
    weather_index = names.index("weather")
    out = os.path.abspath(args.out)
    os.makedirs(os.path.join(out, "tf"), exist_ok=True)
    with open(os.path.join(HERE, "dataset_tf.py.in")) as f:
        template = f.read()
    convoy = os.path.join(args.build, "bin", "convoy")
    from convoy_perception.coco import CocoWriter  # noqa: E402 (after the path)

    merged = CocoWriter(out)
    runs = []
    for k in range(args.runs):
        seed = args.seed + k
        rng = random.Random(seed)
        if kinds:
            kind, weather = draw_weather(rng, kinds[k % len(kinds)])
        elif args.randomize:
            kind, weather = draw_weather(rng)
        else:
            kind, weather = "as configured", {}
        part = os.path.join(out, "parts", "run%03d" % seed)
        shutil.rmtree(part, ignore_errors=True)
        tf = os.path.join(out, "tf", "dataset_tf_%d.py" % seed)
        with open(tf, "w") as f:
            f.write(template.replace("@CAMERA@", args.camera).replace("@WORLD@", args.world)
                    .replace("@EVERY@", str(args.every)))
        cfg = json.loads(json.dumps(base))
        cfg["SimulationTimeout"] = args.seconds
        cfg["EngineConfigs"].append({
            "EngineType": "python_json", "EngineName": "dataset_writer",
            "PythonFileName": os.path.join(HERE, "dataset_writer.py"),
            "EngineTimestep": world.get("EngineTimestep", 0.02),
            "EngineEnvParams": ["CONVOY_DATASET_DIR=" + part, "CONVOY_DATASET_PREFIX=s%d" % seed,
                                "CONVOY_DATASET_EXTRA=" + json.dumps({"seed": seed, "weather_kind": kind})]})
        cfg["DataPackProcessingFunctions"].append({"Name": "dataset_tf", "FileName": tf})
        for e in cfg["EngineConfigs"]:
            if e["EngineName"] == args.world and e.get("EngineType", "").startswith("gazebo"):
                e["GazeboRNGSeed"] = seed
            if e["EngineName"] == "weather":
                e["Seed"] = seed
                e.update(weather)
            if e["EngineName"] == "recorder":
                e["EngineTimestep"] = args.seconds
        models = vary_models(cfg, seed, shares) if shares else {}
        for item in args.set:
            key, _, value = item.partition("=")
            engine, _, field = key.partition(".")
            try:
                value = json.loads(value)
            except ValueError:
                pass
            match = [e for e in cfg["EngineConfigs"] if e["EngineName"] == engine]
            if not match or not field:
                sys.exit("make_dataset: --set %s: no engine '%s' in %s" % (item, engine, config_path))
            match[0][field] = value
        for item in args.env:
            engine, _, var = item.partition(":")
            match = [e for e in cfg["EngineConfigs"] if e["EngineName"] == engine]
            if not match or "=" not in var:
                sys.exit("make_dataset: --env %s: expected ENGINE:VAR=VALUE with an engine of %s" % (item, config_path))
            match[0].setdefault("EngineEnvParams", []).append(var)
        # Relative paths in the config are relative to its folder: the derived config goes
        # next to it for the run, and is removed after.
        derived = os.path.join(os.path.dirname(config_path), ".dataset_%d_%d.json" % (os.getpid(), seed))
        with open(derived, "w") as f:
            json.dump(cfg, f, indent=1)
        try:
            r = subprocess.run([convoy, "run", "-q", "-c", derived, "--run-dir",
                                os.path.join(out, "runs", "run%03d" % seed)],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        finally:
            os.remove(derived)
        if r.returncode != 0:
            sys.exit("make_dataset: run %d failed (exit %d):\n%s" % (seed, r.returncode, r.stderr[-3000:]))
        with open(os.path.join(part, "annotations.json")) as f:
            doc = json.load(f)
        # Merge: move the files up, renumber the ids.
        remap = {}
        for img in doc["images"]:
            for key in ("file_name", "depth_file"):
                if key in img:
                    os.replace(os.path.join(part, img[key]), os.path.join(out, img[key]))
            new_id = len(merged.images) + 1
            remap[img["id"]] = new_id
            merged.images.append(dict(img, id=new_id))
        for a in doc["annotations"]:
            merged.annotations.append(dict(a, id=len(merged.annotations) + 1, image_id=remap[a["image_id"]]))
        shutil.rmtree(part, ignore_errors=True)
        runs.append({"seed": seed, "weather_kind": kind, "weather": weather, "models": models,
                     "frames": len(doc["images"]),
                     "annotations": len(doc["annotations"])})
        print("run %d (seed %d, %s): %d frames, %d annotations" % (k, seed, kind, len(doc["images"]),
                                                                   len(doc["annotations"])), flush=True)
    merged.write({"config": config_path, "runs": runs})
    shutil.rmtree(os.path.join(out, "parts"), ignore_errors=True)
    with open(os.path.join(out, "runs.json"), "w") as f:
        json.dump(runs, f, indent=1)
    print("make_dataset: %d images, %d annotations in %s" % (len(merged.images), len(merged.annotations), out))


if __name__ == "__main__":
    main()
