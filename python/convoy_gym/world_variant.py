"""A copy of an experiment's config whose Gazebo world has another physics step.

The Parkring world's physics (DART) steps every 1 ms, so one 0.05 s environment step is 50 physics steps,
most of its time. variant_config(config, 0.005) writes, in a new temporary folder, the world
with <max_step_size>0.005</max_step_size> and the config pointing at it (its file paths made
absolute, since NRPCoreSim resolves them against the config's folder). The world's own
folder and its models/ stay on the model path through a `models` link beside the copy."""
import json
import os
import re
import shutil
import tempfile

_STEP = re.compile(r"<max_step_size>\s*[^<]*\s*</max_step_size>")


def _absolute_paths(value, folder):
    """The config with every "...File" / "...FileName" string made absolute."""
    if isinstance(value, dict):
        out = {}
        for key, v in value.items():
            if isinstance(v, str) and (key.endswith("File") or key.endswith("FileName")) \
                    and v and not os.path.isabs(v):
                out[key] = os.path.normpath(os.path.join(folder, v))
            else:
                out[key] = _absolute_paths(v, folder)
        return out
    if isinstance(value, list):
        return [_absolute_paths(v, folder) for v in value]
    return value


def variant_config(config, physics_step):
    """Returns (path of the new config, its temporary folder: remove it after the run)."""
    step = float(physics_step)
    if not 0.0 < step <= 0.05:
        raise ValueError("physics_step must be in (0, 0.05] s, got %r" % (physics_step,))
    folder = os.path.dirname(os.path.abspath(config))
    with open(config) as f:
        cfg = _absolute_paths(json.load(f), folder)
    worlds = [e for e in cfg.get("EngineConfigs", []) if e.get("GazeboWorldFile")]
    if not worlds:
        raise ValueError("physics_step: %s has no engine with a GazeboWorldFile" % config)
    tmp = tempfile.mkdtemp(prefix="convoy_gym_")
    try:
        for i, engine in enumerate(worlds):
            world = engine["GazeboWorldFile"]
            with open(world) as f:
                sdf = f.read()
            if not _STEP.search(sdf):
                raise ValueError("physics_step: %s has no <max_step_size>" % world)
            sub = os.path.join(tmp, "world%d" % i)
            os.mkdir(sub)
            models = os.path.join(os.path.dirname(world), "models")
            if os.path.isdir(models):
                os.symlink(models, os.path.join(sub, "models"))
            copy = os.path.join(sub, os.path.basename(world))
            with open(copy, "w") as f:
                f.write(_STEP.sub("<max_step_size>%r</max_step_size>" % step, sdf))
            engine["GazeboWorldFile"] = copy
        path = os.path.join(tmp, os.path.basename(config))
        with open(path, "w") as f:
            json.dump(cfg, f, indent=2)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    return path, tmp
