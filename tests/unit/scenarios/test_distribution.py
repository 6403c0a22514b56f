"""convoy_scenario.distribution (OpenSCENARIO ParameterValueDistribution files) and their
campaign entries (convoy_scenario.distribution_entry): inline
distribution texts, and esmini's cut-in_parameter_set.xosc (tests/data/esmini/xosc) whose 12
variants must be esmini's 12 permutations in esmini's order.

Run: PYTHONPATH=python /usr/bin/python3 -m unittest -v test_distribution (from this folder)."""

import io
import json
import os
import shutil
import statistics
import sys
import tempfile
import unittest
from contextlib import redirect_stderr, redirect_stdout

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(os.path.dirname(HERE)))
sys.path.insert(0, os.path.join(REPO, "python"))

from convoy_scenario import distribution as dist  # noqa: E402
from convoy_scenario.xmltree import ScenarioError  # noqa: E402

ESMINI_XOSC = os.path.join(REPO, "tests", "data", "esmini", "xosc")

SCENARIO = """<?xml version="1.0"?>
<OpenSCENARIO>
  <FileHeader revMajor="1" revMinor="2" date="2026-11-27T00:00:00" description="s" author="t"/>
  <ParameterDeclarations>
    <ParameterDeclaration name="Speed" parameterType="double" value="10"/>
    <ParameterDeclaration name="Gap" parameterType="double" value="20"/>
    <ParameterDeclaration name="Car" parameterType="string" value="car_white"/>
    <ParameterDeclaration name="Lane" parameterType="integer" value="-1"/>
  </ParameterDeclarations>
  <Storyboard/>
</OpenSCENARIO>
"""

HEAD = """<?xml version="1.0"?>
<OpenSCENARIO>
  <FileHeader revMajor="1" revMinor="2" date="2026-11-27T00:00:00" description="d" author="t"/>
  <ParameterValueDistribution>
    <ScenarioFile filepath="scenario.xosc"/>
"""
TAIL = """  </ParameterValueDistribution>
</OpenSCENARIO>
"""


class Base(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.mkdtemp(prefix="convoy_dist_")
        self.addCleanup(shutil.rmtree, self.dir, ignore_errors=True)
        with open(os.path.join(self.dir, "scenario.xosc"), "w") as f:
            f.write(SCENARIO)

    def write(self, body, name="dist.xosc", whole=None):
        path = os.path.join(self.dir, name)
        with open(path, "w") as f:
            f.write(whole if whole is not None else HEAD + body + TAIL)
        return path

    def expand(self, body, seed=0):
        return dist.expand(self.write(body), seed)

    def error(self, body, *parts, seed=0):
        with self.assertRaises(ScenarioError) as cm:
            self.expand(body, seed)
        msg = str(cm.exception)
        for p in parts:
            self.assertIn(p, msg)
        return msg


def values(d):
    return [v.values for v in d.variants]


class Deterministic(Base):
    def test_set_and_names(self):
        d = self.expand("""<Deterministic>
  <DeterministicSingleParameterDistribution parameterName="Car">
    <DistributionSet><Element value="car_blue"/><Element value="van_red"/></DistributionSet>
  </DeterministicSingleParameterDistribution>
</Deterministic>""")
        self.assertEqual(values(d), [{"Car": "car_blue"}, {"Car": "van_red"}])
        self.assertEqual([v.name for v in d.variants], ["dist_001", "dist_002"])
        self.assertEqual(d.variants[1].label, "Car=van_red")
        self.assertEqual(d.scenario_file, os.path.join(self.dir, "scenario.xosc"))
        self.assertEqual((d.kind, d.seed), ("deterministic", None))

    def test_range_inclusive_with_floating_steps(self):
        d = self.expand("""<Deterministic>
  <DeterministicSingleParameterDistribution parameterName="Speed">
    <DistributionRange stepWidth="0.1"><Range lowerLimit="0.1" upperLimit="0.7"/></DistributionRange>
  </DeterministicSingleParameterDistribution>
</Deterministic>""")
        self.assertEqual([v["Speed"] for v in values(d)], [0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7])

    def test_range_step_not_reaching_the_upper_limit(self):
        d = self.expand("""<Deterministic>
  <DeterministicSingleParameterDistribution parameterName="Gap">
    <DistributionRange stepWidth="4"><Range lowerLimit="10" upperLimit="21"/></DistributionRange>
  </DeterministicSingleParameterDistribution>
</Deterministic>""")
        self.assertEqual([v["Gap"] for v in values(d)], [10.0, 14.0, 18.0])

    def test_single_point_range(self):
        d = self.expand("""<Deterministic>
  <DeterministicSingleParameterDistribution parameterName="Gap">
    <DistributionRange stepWidth="1"><Range lowerLimit="5" upperLimit="5"/></DistributionRange>
  </DeterministicSingleParameterDistribution>
</Deterministic>""")
        self.assertEqual(values(d), [{"Gap": 5.0}])

    def test_cartesian_product_last_fastest(self):
        d = self.expand("""<Deterministic>
  <DeterministicMultiParameterDistribution>
    <ValueSetDistribution>
      <ParameterValueSet>
        <ParameterAssignment parameterRef="Car" value="a"/>
        <ParameterAssignment parameterRef="Lane" value="-2"/>
      </ParameterValueSet>
      <ParameterValueSet><ParameterAssignment parameterRef="Car" value="b"/></ParameterValueSet>
    </ValueSetDistribution>
  </DeterministicMultiParameterDistribution>
  <DeterministicSingleParameterDistribution parameterName="Speed">
    <DistributionSet><Element value="5"/><Element value="7"/><Element value="9"/></DistributionSet>
  </DeterministicSingleParameterDistribution>
</Deterministic>""")
        self.assertEqual(len(d.variants), 6)
        self.assertEqual(values(d)[:4], [
            {"Car": "a", "Lane": "-2", "Speed": "5"}, {"Car": "a", "Lane": "-2", "Speed": "7"},
            {"Car": "a", "Lane": "-2", "Speed": "9"}, {"Car": "b", "Speed": "5"}])
        self.assertEqual(d.variants[0].label, "Car=a;Lane=-2;Speed=5")

    def test_errors_name_file_line_element(self):
        msg = self.error("""<Deterministic>
  <DeterministicSingleParameterDistribution parameterName="Speed">
    <DistributionRange stepWidth="0"><Range lowerLimit="1" upperLimit="2"/></DistributionRange>
  </DeterministicSingleParameterDistribution>
</Deterministic>""", "dist.xosc:8: <DistributionRange> stepWidth: must be > 0")
        self.assertTrue(msg.startswith("dist.xosc:8"), msg)
        self.error("""<Deterministic>
  <DeterministicSingleParameterDistribution parameterName="Speed">
    <DistributionRange stepWidth="1"><Range lowerLimit="3" upperLimit="2"/></DistributionRange>
  </DeterministicSingleParameterDistribution>
</Deterministic>""", "dist.xosc:8: <Range> upperLimit 2 is below lowerLimit 3")
        self.error("""<Deterministic>
  <DeterministicSingleParameterDistribution parameterName="Speed">
    <UserDefinedDistribution type="mine">1;2</UserDefinedDistribution>
  </DeterministicSingleParameterDistribution>
</Deterministic>""", "dist.xosc:8: <UserDefinedDistribution> (type 'mine') is not supported")
        self.error("""<Deterministic>
  <DeterministicSingleParameterDistribution parameterName="Nope">
    <DistributionSet><Element value="1"/></DistributionSet>
  </DeterministicSingleParameterDistribution>
</Deterministic>""", "dist.xosc:7: <DeterministicSingleParameterDistribution> parameterName: "
                     "scenario.xosc declares no global parameter Nope")
        self.error("""<Deterministic>
  <DeterministicSingleParameterDistribution parameterName="Speed">
    <DistributionSet><Element value="1"/></DistributionSet>
  </DeterministicSingleParameterDistribution>
  <DeterministicSingleParameterDistribution parameterName="Speed">
    <DistributionSet><Element value="2"/></DistributionSet>
  </DeterministicSingleParameterDistribution>
</Deterministic>""", "dist.xosc:10:", "parameter Speed is varied already", "line 7")
        self.error("""<Deterministic>
  <DeterministicSingleParameterDistribution parameterName="Speed">
    <DistributionRange stepWidth="$step"><Range lowerLimit="1" upperLimit="2"/></DistributionRange>
  </DeterministicSingleParameterDistribution>
</Deterministic>""", "<DistributionRange> stepWidth: '$step'")
        self.error("<Deterministic/>", "dist.xosc:6: <Deterministic> holds no distribution")
        self.error("<Deterministic><Foo/></Deterministic>",
                   "<Foo> is not supported in <Deterministic>")

    def test_missing_scenario_file(self):
        path = self.write("", whole=HEAD.replace("scenario.xosc", "sub/missing.xosc") +
                          "<Deterministic/>" + TAIL)
        with self.assertRaises(ScenarioError) as cm:
            dist.expand(path)
        self.assertIn("dist.xosc:5: <ScenarioFile> filepath: the scenario file %s does not exist"
                      % os.path.join(self.dir, "sub", "missing.xosc"), str(cm.exception))

    def test_not_a_distribution(self):
        with self.assertRaises(ScenarioError) as cm:
            dist.expand(os.path.join(self.dir, "scenario.xosc"))
        self.assertIn("scenario.xosc:2: <OpenSCENARIO> holds no <ParameterValueDistribution>",
                      str(cm.exception))
        self.assertFalse(dist.is_distribution(os.path.join(self.dir, "scenario.xosc")))

    def test_scenario_file_must_be_a_scenario(self):
        other = self.write("<Deterministic/>", name="other.xosc")
        path = self.write("", whole=HEAD.replace("scenario.xosc", os.path.basename(other)) +
                          "<Deterministic/>" + TAIL)
        with self.assertRaises(ScenarioError) as cm:
            dist.expand(path)
        self.assertIn("<ScenarioFile> filepath: other.xosc is not a scenario", str(cm.exception))


STOCHASTIC = """<Stochastic numberOfTestRuns="%d"%s>
  <StochasticDistribution parameterName="Speed">%s</StochasticDistribution>
</Stochastic>"""


class Stochastic(Base):
    def draws(self, inner, n=400, seed=0, file_seed=None):
        attr = ' randomSeed="%s"' % file_seed if file_seed is not None else ""
        d = self.expand(STOCHASTIC % (n, attr, inner), seed)
        return [v.values["Speed"] for v in d.variants], d

    def test_same_seed_same_variants(self):
        body = STOCHASTIC % (5, "", '<NormalDistribution expectedValue="10" variance="4"/>')
        a, b = self.expand(body, seed=3), self.expand(body, seed=3)
        self.assertEqual(values(a), values(b))
        self.assertNotEqual(values(a), values(self.expand(body, seed=4)))
        self.assertEqual((a.kind, a.seed), ("stochastic", 3))
        self.assertEqual([v.name for v in a.variants][-1], "dist_005")

    def test_file_seed_wins(self):
        x, d1 = self.draws('<UniformDistribution><Range lowerLimit="0" upperLimit="1"/></UniformDistribution>',
                           n=3, seed=1, file_seed="7")
        y, d2 = self.draws('<UniformDistribution><Range lowerLimit="0" upperLimit="1"/></UniformDistribution>',
                           n=3, seed=2, file_seed="7")
        self.assertEqual(x, y)
        self.assertEqual(d1.seed, 7.0)

    def test_normal_truncated(self):
        x, _ = self.draws('<NormalDistribution expectedValue="10" variance="4">'
                          '<Range lowerLimit="9" upperLimit="30"/></NormalDistribution>')
        self.assertTrue(all(9 <= v <= 30 for v in x))
        x, _ = self.draws('<NormalDistribution expectedValue="10" variance="4"/>', n=2000)
        self.assertAlmostEqual(statistics.mean(x), 10, delta=0.2)
        self.assertAlmostEqual(statistics.variance(x), 4, delta=0.5)

    def test_lognormal_moments_of_the_value(self):
        x, _ = self.draws('<LogNormalDistribution expectedValue="5" variance="1"/>', n=4000)
        self.assertTrue(all(v > 0 for v in x))
        self.assertAlmostEqual(statistics.mean(x), 5, delta=0.1)
        self.assertAlmostEqual(statistics.variance(x), 1, delta=0.2)

    def test_uniform(self):
        x, _ = self.draws('<UniformDistribution><Range lowerLimit="2" upperLimit="3"/></UniformDistribution>')
        self.assertTrue(all(2 <= v <= 3 for v in x))

    def test_poisson_integers(self):
        for lam in (3.0, 80.0):
            x, _ = self.draws('<PoissonDistribution expectedValue="%g"/>' % lam, n=3000)
            self.assertTrue(all(isinstance(v, int) and v >= 0 for v in x))
            self.assertAlmostEqual(statistics.mean(x), lam, delta=0.06 * lam)
            self.assertAlmostEqual(statistics.variance(x), lam, delta=0.15 * lam)

    def test_histogram_bins_by_weight(self):
        x, _ = self.draws('<Histogram><Bin weight="3"><Range lowerLimit="0" upperLimit="1"/></Bin>'
                          '<Bin weight="1"><Range lowerLimit="10" upperLimit="11"/></Bin>'
                          '<Bin weight="0"><Range lowerLimit="50" upperLimit="51"/></Bin></Histogram>', n=4000)
        low = sum(1 for v in x if 0 <= v <= 1)
        high = sum(1 for v in x if 10 <= v <= 11)
        self.assertEqual(low + high, len(x))
        self.assertAlmostEqual(low / len(x), 0.75, delta=0.03)

    def test_probability_set(self):
        x, _ = self.draws('<ProbabilityDistributionSet><Element value="a" weight="1"/>'
                          '<Element value="b" weight="0"/><Element value="c" weight="1"/>'
                          '</ProbabilityDistributionSet>', n=1000)
        self.assertEqual(set(x), {"a", "c"})
        self.assertAlmostEqual(x.count("a") / len(x), 0.5, delta=0.06)

    def test_several_parameters_in_document_order(self):
        d = self.expand("""<Stochastic numberOfTestRuns="3" randomSeed="1">
  <StochasticDistribution parameterName="Gap"><UniformDistribution><Range lowerLimit="0" upperLimit="1"/></UniformDistribution></StochasticDistribution>
  <StochasticDistribution parameterName="Car"><ProbabilityDistributionSet><Element value="x" weight="1"/></ProbabilityDistributionSet></StochasticDistribution>
</Stochastic>""")
        self.assertEqual([list(v.values) for v in d.variants], [["Gap", "Car"]] * 3)

    def test_errors(self):
        self.error(STOCHASTIC % (0, "", '<PoissonDistribution expectedValue="1"/>'),
                   "dist.xosc:6: <Stochastic> numberOfTestRuns: must be a whole number >= 1")
        self.error(STOCHASTIC % (2, "", '<NormalDistribution expectedValue="1" variance="-1"/>'),
                   "dist.xosc:7: <NormalDistribution> variance: must be >= 0")
        self.error(STOCHASTIC % (2, "", '<NormalDistribution expectedValue="0" variance="1">'
                                 '<Range lowerLimit="100" upperLimit="101"/></NormalDistribution>'),
                   "<NormalDistribution> its Range 100..101 holds too little of the distribution")
        self.error(STOCHASTIC % (2, "", '<UserDefinedDistribution type="x">1</UserDefinedDistribution>'),
                   "dist.xosc:7: <UserDefinedDistribution> (type 'x') is not supported")
        self.error(STOCHASTIC % (2, "", '<ProbabilityDistributionSet><Element value="a" weight="0"/>'
                                 '</ProbabilityDistributionSet>'),
                   "<ProbabilityDistributionSet> the weights add up to 0")
        self.error(STOCHASTIC % (2, "", '<UniformDistribution/>'), "<UniformDistribution> needs a <Range>")
        self.error("<Deterministic/><Stochastic/>",
                   "<ParameterValueDistribution> needs exactly one of <Deterministic>, <Stochastic>")


class EsminiCutIn(unittest.TestCase):
    """esmini's cut-in_parameter_set.xosc: esmini (--param_dist, --param_permutation k,
    --save_xosc) gives permutation k the values below; variant k+1 must be the same."""

    def test_twelve_variants_as_esmini(self):
        d = dist.expand(os.path.join(ESMINI_XOSC, "cut-in_parameter_set.xosc"))
        self.assertEqual(d.scenario_file, os.path.join(ESMINI_XOSC, "cut-in.xosc"))
        self.assertEqual(len(d.variants), 12)
        labels = [v.label for v in d.variants]
        self.assertEqual(labels[0], "HostVehicle=car_blue;TargetVehicle=car_yellow;EgoSpeed=70.0;TargetSpeedFactor=1.1")
        self.assertEqual(labels[4], "HostVehicle=car_blue;TargetVehicle=car_yellow;EgoSpeed=110.0;TargetSpeedFactor=1.3")
        self.assertEqual(labels[7], "TargetVehicle=van_red;EgoSpeed=70.0;TargetSpeedFactor=1.3")
        self.assertEqual(labels[11], "TargetVehicle=van_red;EgoSpeed=110.0;TargetSpeedFactor=1.5")
        self.assertEqual([v.name for v in d.variants][::11],
                         ["cut-in_parameter_set_001", "cut-in_parameter_set_012"])

    def test_command_line(self):
        out, err = io.StringIO(), io.StringIO()
        with redirect_stdout(out), redirect_stderr(err):
            code = dist.main([os.path.join(ESMINI_XOSC, "cut-in_parameter_set.xosc")])
        self.assertEqual(code, 0)
        lines = out.getvalue().splitlines()
        self.assertEqual(len(lines), 12)
        self.assertEqual(json.loads(lines[2]), {"HostVehicle": "car_blue", "TargetVehicle": "car_yellow",
                                                "EgoSpeed": "70.0", "TargetSpeedFactor": 1.5})
        self.assertIn("12 variants of", err.getvalue())
        with redirect_stdout(io.StringIO()), redirect_stderr(err):
            self.assertEqual(dist.main([os.path.join(ESMINI_XOSC, "cut-in.xosc")]), 2)
        self.assertIn("error: cut-in.xosc:", err.getvalue())


class CampaignEntries(Base):
    """A folder suite holding a distribution: one task per variant, its parameters given as
    convoy run --scenario-param."""

    def test_plan(self):
        from convoy_campaign import results, suite
        from convoy_scenario import campaign_entry, distribution_entry
        campaign_entry.register()
        distribution_entry.register()
        self.write("""<Deterministic>
  <DeterministicSingleParameterDistribution parameterName="Speed">
    <DistributionSet><Element value="8"/><Element value="12.5"/></DistributionSet>
  </DeterministicSingleParameterDistribution>
</Deterministic>""", name="speeds.xosc")
        entries = suite.load_suite(self.dir)
        self.assertEqual([e["name"] for e in entries], ["scenario", "speeds_001", "speeds_002"])
        self.assertEqual(entries[2]["parameters"], {"Speed": "12.5"})
        plan = suite.make_plan(entries, 1, ["clear"], os.path.join(self.dir, "out"), "/x/bin/convoy", 2.0,
                               record=True)
        task = plan["tasks"][2]
        self.assertEqual(task["parameters"], {"Speed": "12.5"})
        self.assertEqual(task["config"], os.path.join(self.dir, "scenario.xosc"))
        argv = task["argv"]
        self.assertEqual(argv[:3], ["/x/bin/convoy", "run", "--record"])
        self.assertEqual(argv[argv.index("--scenario") + 1], os.path.join(self.dir, "scenario.xosc"))
        self.assertEqual(argv[-2:], ["--scenario-param", 'Speed="12.5"'])
        self.assertIn("SimulationTimeout=2.0", argv)
        rows = results.leaderboard_rows([{"scenario": "speeds_002", "seed": 0, "weather": "clear",
                                          "parameters": task["parameters"], "score": None,
                                          "exit_code": 0, "wall_s": 1.0}])
        self.assertEqual(rows[0]["parameters"], "Speed=12.5")

    def test_bad_distribution_is_bad_input(self):
        from convoy_campaign import suite
        from convoy_scenario import campaign_entry, distribution_entry
        campaign_entry.register()
        distribution_entry.register()
        self.write("<Deterministic/>", name="bad.xosc")
        with self.assertRaises(suite.SuiteError) as cm:
            suite.load_suite(self.dir)
        self.assertIn("bad.xosc:6: <Deterministic> holds no distribution", str(cm.exception))


if __name__ == "__main__":
    unittest.main()
