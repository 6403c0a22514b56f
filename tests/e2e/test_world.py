"""End-to-end tests of the world engine (gazebo_grpc) under the coordinator: the wheeled
robot example, joint and link datapacks in TFs, the gazebo_json alias, bad SDF input.

Run with Debian's /usr/bin/python3 -m unittest test_world."""

import csv
import json
import os
import shutil
import subprocess
import tempfile
import textwrap
import unittest

from test_core import CONVOY, Experiment

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
ROBOT = os.path.join(REPO, "experiments", "wheeled_robot")


class WorldEngine(unittest.TestCase):
    def run_robot(self, seconds, *extra):
        d = tempfile.mkdtemp(prefix="convoy-world-")
        self.addCleanup(shutil.rmtree, d, True)
        r = subprocess.run([CONVOY, "run", "-q", "-c", os.path.join(ROBOT, "simulation_config.json"),
                            "--run-dir", os.path.join(d, "run"), "-o", "SimulationTimeout=%g" % seconds]
                           + list(extra), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                           timeout=120)
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(os.path.join(d, "run", "trajectory.csv")) as f:
            return list(csv.DictReader(f))

    def test_wheeled_robot_example_drives_to_its_first_waypoint(self):
        rows = self.run_robot(4)
        self.assertEqual(len(rows), 200)
        first, last = rows[0], rows[-1]
        self.assertLess(abs(float(first["x"])), 0.05)
        # heading for (2, 1): it moved that way and is driving
        self.assertGreater(float(last["x"]), 1.0)
        self.assertGreater(float(last["y"]), 0.3)
        self.assertGreater(float(last["speed"]), 0.3)

    def test_alias_gazebo_json_and_determinism(self):
        a = self.run_robot(2)
        b = self.run_robot(2, "-o", "EngineConfigs/0/EngineType=gazebo_json")
        self.assertEqual(a, b)

    def test_joint_and_link_datapacks_in_a_tf(self):
        ex = Experiment(self)
        shutil.copy(os.path.join(ROBOT, "world.sdf"), os.path.join(ex.dir, "world.sdf"))
        ex.engines.append({"EngineType": "gazebo_grpc", "EngineName": "gazebo",
                           "GazeboWorldFile": "world.sdf", "EngineTimestep": 0.01})
        ex.engine("probe", textwrap.dedent("""\
            import json, os
            from nrp_core.engines.python_json import EngineScript
            class Script(EngineScript):
                def initialize(self):
                    self._registerDataPack("seen")
                    self.log = []
                def runLoop(self, timestep_ns):
                    self.log.append(self._getDataPack("seen"))
                def shutdown(self):
                    with open(os.path.join(os.path.dirname(__file__), "seen.json"), "w") as f:
                        json.dump(self.log, f)
            """))
        ex.function("tf", textwrap.dedent("""\
            from nrp_core import *
            from nrp_core.data.nrp_json import *
            from nrp_core.data.nrp_protobuf import GazeboJointDataPack

            @EngineDataPack(keyword='wheel', id=DataPackIdentifier('robot_joint_plugin::j_fl', 'gazebo'))
            @EngineDataPack(keyword='wheel_scoped', id=DataPackIdentifier('robot::j_fl', 'gazebo'))
            @EngineDataPack(keyword='chassis', id=DataPackIdentifier('robot_link_plugin::chassis', 'gazebo'))
            @TransceiverFunction("gazebo")
            def spin(wheel, wheel_scoped, chassis):
                out = []
                for j in ("j_fl", "j_fr", "j_rl", "j_rr"):
                    dp = GazeboJointDataPack("robot_joint_plugin::" + j, "gazebo")
                    dp.data.velocity = 4.0
                    out.append(dp)
                return out

            @EngineDataPack(keyword='wheel', id=DataPackIdentifier('robot_joint_plugin::j_fl', 'gazebo'))
            @EngineDataPack(keyword='chassis', id=DataPackIdentifier('robot::chassis', 'gazebo'))
            @TransceiverFunction("probe")
            def report(wheel, chassis):
                return [JsonDataPack("seen", "probe", {
                    "velocity": wheel.data.velocity, "position": wheel.data.position,
                    "effort": wheel.data.effort, "x": float(chassis.data.pos[0]),
                    "qw": float(chassis.data.rotation[3])})]
            """))
        ex.run(3.0)
        with open(os.path.join(ex.dir, "seen.json")) as f:
            seen = [s for s in json.load(f) if s]
        last = seen[-1]
        self.assertAlmostEqual(last["velocity"], 4.0, delta=0.1)
        self.assertGreater(last["position"], 5.0)   # turned several radians
        self.assertGreater(last["x"], 0.8)          # ~0.4 m/s for ~3 s
        self.assertAlmostEqual(last["qw"], 1.0, delta=0.01)

    def test_physics_keeps_time_with_any_engine_timestep(self):
        # A ball falls freely: after the engine's k-th step its speed is g k dt_engine, to
        # within half a physics step (1 ms), whether the engine step is shorter than the
        # physics step or no multiple of it (1/30 s).
        for timestep in (0.0005, 1 / 30):
            ex = Experiment(self)
            shutil.copy(os.path.join(HERE, "..", "world", "data", "physics_basics.sdf"),
                        os.path.join(ex.dir, "world.sdf"))
            ex.engines.append({"EngineType": "gazebo_grpc", "EngineName": "gazebo",
                               "GazeboWorldFile": "world.sdf", "EngineTimestep": timestep})
            ex.engine("probe", textwrap.dedent("""\
                import json, os
                from nrp_core.engines.python_json import EngineScript
                class Script(EngineScript):
                    def initialize(self):
                        self._registerDataPack("vz")
                        self.log = []
                    def runLoop(self, timestep_ns):
                        self.log.append(self._getDataPack("vz"))
                    def shutdown(self):
                        with open(os.path.join(os.path.dirname(__file__), "vz.json"), "w") as f:
                            json.dump(self.log, f)
                """), timestep=timestep)
            ex.function("tf", textwrap.dedent("""\
                from nrp_core import *
                from nrp_core.data.nrp_json import *
                @EngineDataPack(keyword='ball', id=DataPackIdentifier('ball_link_plugin::body', 'gazebo'))
                @TransceiverFunction("probe")
                def tf(ball):
                    return [JsonDataPack("vz", "probe", float(ball.data.lin_vel[2]))]
                """))
            ex.run(0.5)
            with open(os.path.join(ex.dir, "vz.json")) as f:
                vz = json.load(f)
            self.assertGreaterEqual(len(vz), 14, timestep)
            for k, v in enumerate(vz):
                self.assertAlmostEqual(v, -9.81 * k * timestep, delta=9.81 * 0.0006,
                                       msg="step %d of %g s" % (k, timestep))

    def test_camera_datapack_comes_only_with_a_new_frame(self):
        # A 10 Hz camera read every 0.02 s step: as NRP-Core's camera controller, the engine
        # sends its datapack only after a new frame; in between, TFs get the last one with
        # isUpdated() False, intact (its shared memory is not reused meanwhile, even when the
        # same replies carry another camera's frames).
        for cameras in (["noisy_camera::cam"], ["noisy_camera::cam", "clean_camera::cam"]):
            ex = Experiment(self)
            shutil.copy(os.path.join(HERE, "..", "world", "data", "camera_world.sdf"),
                        os.path.join(ex.dir, "world.sdf"))
            ex.engines.append({"EngineType": "gazebo_grpc", "EngineName": "gazebo",
                               "GazeboWorldFile": "world.sdf", "EngineTimestep": 0.02})
            decorators = "".join("@EngineDataPack(keyword='c%d', id=DataPackIdentifier(%r, 'gazebo'))\n"
                                 % (i, c) for i, c in enumerate(cameras))
            args = ", ".join("c%d" % i for i in range(len(cameras)))
            ex.function("tf", "import hashlib, json, os\nfrom nrp_core import *\n" + decorators +
                        "@TransceiverFunction('gazebo')\ndef tf(%s):\n" % args +
                        "    with open(os.path.join(os.path.dirname(__file__), 'seen.jsonl'), 'a') as f:\n"
                        "        f.write(json.dumps([[c.isUpdated(), hashlib.md5(c.data.image_data.tobytes())"
                        ".hexdigest()] for c in (%s,)]) + '\\n')\n" % args +
                        "    return []\n")
            ex.run(1.0)
            with open(os.path.join(ex.dir, "seen.jsonl")) as f:
                seen = [json.loads(line) for line in f]
            self.assertGreaterEqual(len(seen), 50)
            noisy = [s[0] for s in seen]
            self.assertTrue(noisy[0][0])
            # Frames at t = 0, 0.1, ..., 1.0, each the same bytes until the next (the noise
            # makes every frame differ).
            changes = [i for i in range(1, len(noisy)) if noisy[i][1] != noisy[i - 1][1]]
            self.assertIn(len(changes) + 1, (10, 11), noisy)
            self.assertEqual(len({h for _, h in noisy}), len(changes) + 1, noisy)
            if len(cameras) == 1:
                for i in range(1, len(noisy)):
                    self.assertEqual(noisy[i][0], i in changes, (i, noisy))
            else:
                # The clean camera renders every step, so every reply carries a frame: the
                # noisy camera's unchanged one comes again with it.
                self.assertTrue(all(s[1][0] for s in seen))

    def test_a_frame_is_copied_twice_from_readback_to_the_detector(self):
        # The world engine converts each frame once, straight into its outgoing shared memory;
        # a TF relaying it (only new frames) costs the coordinator one copy into the
        # detector's shared memory; the detector reads it in place. summary.json counts the
        # copies of frame-sized payloads of every process.
        ex = Experiment(self)
        shutil.copy(os.path.join(HERE, "..", "world", "data", "camera_world.sdf"),
                    os.path.join(ex.dir, "world.sdf"))
        ex.engines.append({"EngineType": "gazebo_grpc", "EngineName": "gazebo",
                           "GazeboWorldFile": "world.sdf", "EngineTimestep": 0.02})
        ex.engines.append({"EngineType": "detector", "EngineName": "det", "Backend": "hog",
                           "EngineTimestep": 0.02})
        ex.function("tf", textwrap.dedent("""\
            import json, os
            from nrp_core import *
            from nrp_core.data.nrp_protobuf import GazeboCameraDataPack

            @EngineDataPack(keyword='cam', id=DataPackIdentifier('noisy_camera::cam', 'gazebo'))
            @EngineDataPack(keyword='dets', id=DataPackIdentifier('detections', 'det'))
            @TransceiverFunction('det')
            def tf(cam, dets):
                if not dets.isEmpty():
                    with open(os.path.join(os.path.dirname(__file__), 'frames.txt'), 'w') as f:
                        f.write(str(dets.data['frame']))
                if not cam.isUpdated():
                    return []
                with open(os.path.join(os.path.dirname(__file__), 'relays.txt'), 'a') as f:
                    f.write('x')
                out = GazeboCameraDataPack('camera', 'det')
                out.data = cam.data
                return [out]
            """))
        ex.run(1.0)
        with open(os.path.join(ex.dir, "relays.txt")) as f:
            relays = len(f.read())
        with open(os.path.join(ex.dir, "frames.txt")) as f:
            detected = int(f.read())
        with open(os.path.join(ex.dir, "run", "summary.json")) as f:
            copies = json.load(f)["frame_copies"]
        self.assertIn(relays, (10, 11))
        self.assertGreaterEqual(detected, relays - 1)  # the last one may come after the end
        self.assertEqual(copies["gazebo"], relays)
        self.assertEqual(copies["coordinator"], relays)
        self.assertEqual(copies["det"], 0)

    def test_sdf_models_are_inserted_at_their_init_pose(self):
        ex = Experiment(self)
        data = os.path.join(HERE, "..", "world", "data")
        shutil.copy(os.path.join(data, "include_world.sdf"), os.path.join(ex.dir, "world.sdf"))
        ex.engines.append({"EngineType": "gazebo_grpc", "EngineName": "gazebo", "GazeboWorldFile": "world.sdf",
                           "EngineEnvParams": ["CONVOY_MODEL_PATH=" + os.path.join(data, "models")],
                           "GazeboSDFModels": [{"Name": "tower_b", "File": "tower.sdf",
                                                "InitPose": [-4, 1, 0, 0, 0, 1.5708]}]})
        # the included model, with a link plugin added
        with open(os.path.join(data, "models", "tower", "model.sdf")) as f:
            text = f.read().replace("<model name=\"tower\">",
                                    "<model name=\"tower\">\n    <plugin name=\"tower_links\" "
                                    "filename=\"NRPGazeboGrpcLinkControllerPlugin.so\"/>")
        ex.file("tower.sdf", text)
        os.makedirs(os.path.join(ex.dir, "meshes"), exist_ok=True)
        shutil.copy(os.path.join(data, "models", "tower", "meshes", "block.obj"), os.path.join(ex.dir, "meshes"))
        ex.engine("probe", textwrap.dedent("""\
            import json, os
            from nrp_core.engines.python_json import EngineScript
            class Script(EngineScript):
                def initialize(self):
                    self._registerDataPack("pos")
                def runLoop(self, timestep_ns):
                    with open(os.path.join(os.path.dirname(__file__), "pos.json"), "w") as f:
                        json.dump(self._getDataPack("pos"), f)
            """))
        ex.function("tf", textwrap.dedent("""\
            from nrp_core import *
            from nrp_core.data.nrp_json import *
            @EngineDataPack(keyword='base', id=DataPackIdentifier('tower_links::base', 'gazebo'))
            @TransceiverFunction("probe")
            def tf(base):
                return [JsonDataPack("pos", "probe", [float(v) for v in base.data.pos] +
                                                     [float(v) for v in base.data.rot])]
            """))
        ex.run(0.2)
        with open(os.path.join(ex.dir, "pos.json")) as f:
            pos = json.load(f)
        self.assertAlmostEqual(pos[0], -4, delta=0.01)
        self.assertAlmostEqual(pos[1], 1, delta=0.01)
        self.assertAlmostEqual(pos[2], 0.5, delta=0.02)
        self.assertAlmostEqual(abs(pos[5]), 0.7071, delta=0.01)  # yaw 90 degrees

    def test_bad_sdf_names_the_file_and_engine(self):
        ex = Experiment(self)
        ex.file("world.sdf", "<sdf version='1.7'><world name='w'><model name='m'>")
        ex.engines.append({"EngineType": "gazebo_grpc", "EngineName": "gazebo",
                           "GazeboWorldFile": "world.sdf"})
        r = ex.run(0.1, expect=2)  # the user's world file: exit 2
        self.assertIn("engine 'gazebo'", r.stderr)
        self.assertIn("world.sdf", r.stderr)

    def test_unknown_joint_in_plugin_is_named(self):
        ex = Experiment(self)
        with open(os.path.join(ROBOT, "world.sdf")) as f:
            text = f.read().replace("<j_rr P=", "<j_zz P=")
        ex.file("world.sdf", text)
        ex.engines.append({"EngineType": "gazebo_grpc", "EngineName": "gazebo",
                           "GazeboWorldFile": "world.sdf"})
        r = ex.run(0.1, expect=2)
        self.assertIn("plugin 'robot_joint_plugin': unknown joint 'j_zz'", r.stderr)


if __name__ == "__main__":
    unittest.main()
