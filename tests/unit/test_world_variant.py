"""convoy_gym.world_variant: the world copy's physics step, <max_contacts> and joint
controller gains (DrivingEnv's defaults at a 10 ms step), and their bad input."""
import json
import os
import re
import shutil
import unittest

from convoy_gym.world_variant import variant_config

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
CONFIG = os.path.join(REPO, "experiments", "rl_parkring", "gym_config.json")
STEERING = ("front_left_steering_joint", "front_right_steering_joint")


class WorldVariant(unittest.TestCase):
    def variant(self, **kw):
        path, tmp = variant_config(CONFIG, **kw)
        self.addCleanup(shutil.rmtree, tmp, True)
        with open(path) as f:
            world = json.load(f)["EngineConfigs"][0]["GazeboWorldFile"]
        return world

    def read(self, path):
        with open(path) as f:
            return f.read()

    def test_physics_step_and_max_contacts(self):
        sdf = self.read(self.variant(physics_step=0.01, max_contacts=1))
        physics = re.search(r"<physics\b.*?</physics>", sdf, re.S).group(0)
        self.assertIn("<max_step_size>0.01</max_step_size>", physics)
        self.assertIn("<max_contacts>1</max_contacts>", physics)
        again = self.read(self.variant(max_contacts=3))  # unchanged step, the bound replaced
        self.assertIn("<max_step_size>0.001</max_step_size>", again)
        self.assertEqual(re.findall(r"<max_contacts>(\d+)</max_contacts>", again), ["3"])

    def test_gains_rewrite_the_models_controller_entries(self):
        world = self.variant(physics_step=0.01, gains={j: (4000, 0, 40) for j in STEERING})
        models = os.path.join(os.path.dirname(world), "models")
        car = os.path.join(models, "smart_car")
        self.assertFalse(os.path.islink(car), "the car's model is a rewritten copy")
        self.assertTrue(os.path.islink(os.path.join(car, "meshes")))
        sdf = self.read(os.path.join(car, "model.sdf"))
        for joint in STEERING:
            entry = re.search(r"<%s\b[^>]*>" % joint, sdf).group(0)
            self.assertIn("P='4000.0'", entry)
            self.assertIn("I='0.0'", entry)
            self.assertIn("D='40.0'", entry)
            self.assertIn("Type='position'", entry)
        wheel = re.search(r"<rear_left_wheel_joint\b[^>]*>", sdf).group(0)
        self.assertIn("P='10'", wheel)  # other entries keep theirs
        original = self.read(os.path.join(REPO, "experiments", "autonomous_driving", "models",
                                          "smart_car", "model.sdf"))
        self.assertIn("P='40000.0'", original)  # the experiment's own model is untouched

    def test_bad_input(self):
        with self.assertRaisesRegex(ValueError, "no joint controller entry.*no_such_joint"):
            variant_config(CONFIG, gains={"no_such_joint": (1, 0, 0)})
        with self.assertRaisesRegex(ValueError, "max_contacts must be an int >= 1, got 0"):
            variant_config(CONFIG, max_contacts=0)


if __name__ == "__main__":
    unittest.main()
