"""A copy of an experiment's config whose Gazebo world has another physics step, or whose
cameras render another size once per step.

The Parkring world's physics (DART) steps every 1 ms, so one 0.05 s environment step is 50 physics steps,
most of its time. variant_config(config, 0.005) writes, in a new temporary folder, the world
with <max_step_size>0.005</max_step_size> and the config pointing at it (its file paths made
absolute, since NRPCoreSim resolves them against the config's folder). The world's own
folder and its models/ stay on the model path through a `models` link beside the copy.

variant_config(config, camera=(H, W)) also gives every camera sensor of the world and of the
models in its models/ folder an H x W image and an update_rate of one frame per step of the
config's smallest EngineTimestep (the models carrying one are copied: their other files
linked, model.sdf rewritten), and runs the status function `<name>_camera.py` beside the
config's `<name>.py` (rl_parkring: observe_camera.py, which returns the frame). The world
engine's sun shadow map is then sized to the camera (shadow_distance(): 30 m ahead for 84 x 84 instead of
60, the engine's ShadowDistance; shadow_map_size(): 128 texels a side over it instead of 1024,
the engine's ShadowMapSize; each unless the config sets one), and
shadows=False turns the cameras' shadows off (the engine's Shadows)."""
import json
import os
import re
import shutil
import tempfile

_STEP = re.compile(r"<max_step_size>\s*[^<]*\s*</max_step_size>")
_PHYSICS = re.compile(r"<physics\b[^>]*>.*?</physics>", re.S)
_MAX_CONTACTS = re.compile(r"<max_contacts>\s*[^<]*\s*</max_contacts>")
_CAMERA = re.compile(r"<sensor\b[^>]*\btype\s*=\s*['\"]camera['\"][^>]*>.*?</sensor>", re.S)


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


def _resized_cameras(sdf, camera, rate):
    """(the SDF with every camera sensor's image H x W and update_rate `rate`, how many)."""
    height, width = camera

    def resize(m):
        s = re.sub(r"<width>\s*\d+\s*</width>", "<width>%d</width>" % width, m.group(0))
        s = re.sub(r"<height>\s*\d+\s*</height>", "<height>%d</height>" % height, s)
        if re.search(r"<update_rate>", s):
            return re.sub(r"<update_rate>[^<]*</update_rate>",
                          "<update_rate>%r</update_rate>" % rate, s)
        return s.replace("</sensor>", "<update_rate>%r</update_rate></sensor>" % rate)
    return _CAMERA.subn(resize, sdf)


def _with_gains(sdf, gains):
    """(the SDF with the joint controller entries named in `gains` ({joint: (P, I, D)}, as in
    NRPGazeboGrpcJointControllerPlugin's `<joint P='..' I='..' D='..' .../>`) given those
    gains, how many entries changed)."""
    count = 0
    for joint, pid in gains.items():
        def put(m):
            attrs = m.group(2)
            for name, value in zip("PID", pid):
                attrs = re.sub(r"\b%s\s*=\s*(['\"])[^'\"]*\1" % name, "%s='%r'" % (name, float(value)),
                               attrs)
            return m.group(1) + attrs
        sdf, n = re.subn(r"(<%s\b)([^>]*\bType\s*=[^>]*)" % re.escape(joint), put, sdf)
        count += n
    return sdf, count


def _models_rewritten(models, dest, rewrite):
    """dest/: a link to each model of the folder `models`, but a copy of those that
    rewrite(sdf) -> (sdf, n) changes (n > 0; their files linked, model.sdf rewritten).
    Returns the sum of the n."""
    os.mkdir(dest)
    count = 0
    for name in sorted(os.listdir(models)):
        src = os.path.join(models, name)
        sdf_path = os.path.join(src, "model.sdf")
        n = 0
        if os.path.isfile(sdf_path):
            with open(sdf_path) as f:
                sdf, n = rewrite(f.read())
        if not n:
            os.symlink(src, os.path.join(dest, name))
            continue
        count += n
        os.mkdir(os.path.join(dest, name))
        for entry in os.listdir(src):
            if entry != "model.sdf":
                os.symlink(os.path.join(src, entry), os.path.join(dest, name, entry))
        with open(os.path.join(dest, name, "model.sdf"), "w") as f:
            f.write(sdf)
    return count


FULL_SHADOW_DISTANCE = 60.0  # m: the world engine's default ShadowDistance
FULL_SHADOW_WIDTH = 168      # pixels: a camera this wide or wider gets all of it


def shadow_distance(camera):
    """How far ahead of an H x W camera the sun's shadows are drawn: the world engine's 60 m
    for an image at least 168 pixels wide, less for a smaller one, in proportion (30 m at 84),
    at least 20 m. A shadow there spans as many pixels as one 60 m away in a 168-pixel
    image: about one, less than the blur of the image itself."""
    return max(20.0, FULL_SHADOW_DISTANCE * min(1.0, max(camera) / FULL_SHADOW_WIDTH))


def shadow_map_size(camera):
    """The sun's shadow map for an H x W camera: the power of two of at least 3 texels per
    pixel of the image's larger side over the full 60 m, scaled to shadow_distance(camera),
    in [64, 1024] (1024: the world engine's default). For 84 x 84: 128 texels over 30 m, 0.23 m
    a texel, about what a pixel of an 84-pixel-wide, 90-degree image spans 10 m away."""
    need = 3 * max(camera) * shadow_distance(camera) / FULL_SHADOW_DISTANCE
    size = 64
    while size < need and size < 1024:
        size *= 2
    return size


def check_camera(camera):
    try:
        height, width = (int(v) for v in camera)
    except (TypeError, ValueError):
        raise ValueError("camera must be None or (H, W) in pixels, got %r"
                         % (camera,)) from None
    if not (1 <= height <= 4096 and 1 <= width <= 4096):
        raise ValueError("camera must be (H, W) with 1..4096 pixels each, got %r" % (camera,))
    return height, width


def _camera_status(cfg, config):
    """Points the config's status function at `<name>_camera.py` beside its file."""
    status = cfg.get("StatusFunction") or {}
    path = status.get("FileName", "")
    stem, ext = os.path.splitext(path)
    camera_file = stem + "_camera" + ext
    if not path or not os.path.isfile(camera_file):
        raise ValueError("camera: %s's status function has no camera variant %s (the status "
                         "function returning the camera frame)" % (config, camera_file or "?"))
    status["FileName"] = camera_file


def _with_max_contacts(sdf, world, max_contacts):
    """The world's <physics> with <max_contacts>max_contacts</max_contacts>."""
    tag = "<max_contacts>%d</max_contacts>" % max_contacts

    def put(m):
        block = m.group(0)
        if _MAX_CONTACTS.search(block):
            return _MAX_CONTACTS.sub(tag, block)
        return block.replace("</physics>", tag + "</physics>")
    sdf, n = _PHYSICS.subn(put, sdf)
    if not n:
        raise ValueError("max_contacts: %s has no <physics>" % world)
    return sdf


def _world_copy(world, sub, physics_step, camera, rate, max_contacts=None, gains=None):
    """Writes `world` (with its changes) into the folder `sub`; returns the copy's path."""
    with open(world) as f:
        sdf = f.read()
    if physics_step is not None:
        if not _STEP.search(sdf):
            raise ValueError("physics_step: %s has no <max_step_size>" % world)
        sdf = _STEP.sub("<max_step_size>%r</max_step_size>" % physics_step, sdf)
    if max_contacts is not None:
        sdf = _with_max_contacts(sdf, world, max_contacts)
    models = os.path.join(os.path.dirname(world), "models")
    tally = {"cameras": 0, "gains": 0}

    def rewrite(text):
        """(text with this variant's changes, how many changes)."""
        n = 0
        if camera is not None:
            text, k = _resized_cameras(text, camera, rate)
            tally["cameras"] += k
            n += k
        if gains:
            text, k = _with_gains(text, gains)
            tally["gains"] += k
            n += k
        return text, n
    sdf = rewrite(sdf)[0]
    if os.path.isdir(models):
        if camera is None and not gains:
            os.symlink(models, os.path.join(sub, "models"))
        else:
            _models_rewritten(models, os.path.join(sub, "models"), rewrite)
    if camera is not None and not tally["cameras"]:
        raise ValueError("camera: %s and its models/ have no camera sensor" % world)
    if gains and tally["gains"] < len(gains):
        raise ValueError("joint gains: %s and its models/ have no joint controller entry for "
                         "some of %s" % (world, ", ".join(sorted(gains))))
    copy = os.path.join(sub, os.path.basename(world))
    with open(copy, "w") as f:
        f.write(sdf)
    return copy


def variant_config(config, physics_step=None, camera=None, shadows=True, max_contacts=None,
                   gains=None):
    """Returns (path of the new config, its temporary folder: remove it after the run).
    physics_step: the worlds' physics step in s (None: unchanged); camera: (H, W) or None;
    shadows: False turns the cameras' sun shadows off; max_contacts: the worlds'
    <physics><max_contacts>, contacts kept per pair of collision shapes (None: unchanged);
    gains: {joint name: (P, I, D)} for the joint controller plugin entries of those joints in
    the world and its models/ (None: unchanged)."""
    if max_contacts is not None and (not isinstance(max_contacts, int) or max_contacts < 1):
        raise ValueError("max_contacts must be an int >= 1, got %r" % (max_contacts,))
    if physics_step is not None:
        physics_step = float(physics_step)
        if not 0.0 < physics_step <= 0.05:
            raise ValueError("physics_step must be in (0, 0.05] s, got %r" % (physics_step,))
    if camera is not None:
        camera = check_camera(camera)
    folder = os.path.dirname(os.path.abspath(config))
    with open(config) as f:
        cfg = _absolute_paths(json.load(f), folder)
    engines = cfg.get("EngineConfigs", [])
    worlds = [e for e in engines if e.get("GazeboWorldFile")]
    if not worlds:
        raise ValueError("%s has no engine with a GazeboWorldFile" % config)
    steps = [float(e["EngineTimestep"]) for e in engines if e.get("EngineTimestep")]
    rate = 1.0 / min(steps) if steps else 20.0  # one frame per step of the loop
    if camera is not None:
        _camera_status(cfg, config)
        for engine in worlds:
            engine.setdefault("ShadowMapSize", shadow_map_size(camera))
            engine.setdefault("ShadowDistance", shadow_distance(camera))
            if not shadows:
                engine["Shadows"] = False
    tmp = tempfile.mkdtemp(prefix="convoy_gym_")
    try:
        for i, engine in enumerate(worlds):
            sub = os.path.join(tmp, "world%d" % i)
            os.mkdir(sub)
            engine["GazeboWorldFile"] = _world_copy(engine["GazeboWorldFile"], sub,
                                                    physics_step, camera, rate, max_contacts,
                                                    gains)
        path = os.path.join(tmp, os.path.basename(config))
        with open(path, "w") as f:
            json.dump(cfg, f, indent=2)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    return path, tmp
