"""OpenSCENARIO parameter distributions (ParameterValueDistribution, OpenSCENARIO 1.1-1.3):
a file that names a scenario (ScenarioFile, relative to the distribution file) and how its
global parameters vary, expanded into the concrete runs (variants) of that scenario.

    expand(path, seed=0) -> Distribution(path, scenario_file, kind, seed, variants)
    /usr/bin/python3 -m convoy_scenario.distribution FILE [--seed N]

Deterministic: each DeterministicSingleParameterDistribution (DistributionSet: its Elements;
DistributionRange: lowerLimit, lowerLimit + stepWidth, ... up to upperLimit inclusive, with a
tolerance of 1e-9 of the limits for floating steps) and each
DeterministicMultiParameterDistribution (a ValueSetDistribution: each ParameterValueSet is one
choice, assigning one or more parameters) is a list of choices; the variants are their
cartesian product in document order, the last distribution varying fastest (as esmini's
permutations). A parameter may be varied by one distribution only.

Stochastic (numberOfTestRuns runs, randomSeed): the seed is the file's randomSeed when it has
one, else `seed`; one random.Random(seed) draws, run after run, one value per
StochasticDistribution in document order, so that the same seed gives the same variants:
- NormalDistribution: expectedValue, variance (>= 0); an optional Range truncates it (values
  outside are drawn again);
- LogNormalDistribution: expectedValue (> 0) and variance are the mean and variance of the
  value itself (not of its logarithm); optional Range as Normal;
- UniformDistribution: uniform over its Range;
- PoissonDistribution: expectedValue (> 0), an integer value; optional Range as Normal;
- Histogram: a Bin chosen by its weight, then a value uniform over the Bin's Range;
- ProbabilityDistributionSet: an Element's value (as written) chosen by its weight.
UserDefinedDistribution (deterministic or stochastic) is refused: its meaning belongs to the
tool that defines it.

Values: a DistributionSet's, ParameterValueSet's or ProbabilityDistributionSet's value is
the text as written (the scenario converts it to the parameter's declared type); ranges and
the continuous distributions give numbers (Poisson an integer). Every varied parameter must
be a global parameter of the scenario (its top-level ParameterDeclarations).

Each variant is named `<file stem>_<NNN>` (1-based, zero-padded to 3 digits or more) and has a
label `name=value;...` of its parameters. Errors raise one ScenarioError naming
file:line: <Element>.
"""

import argparse
import itertools
import json
import math
import os
import random
import sys
from dataclasses import dataclass

from .xmltree import ScenarioError, parse_file

MAX_REDRAWS = 10000  # draws of a truncated distribution before its Range is called too narrow
DETERMINISTIC = ("DeterministicMultiParameterDistribution", "DeterministicSingleParameterDistribution")
SINGLE_KINDS = ("DistributionSet", "DistributionRange", "UserDefinedDistribution")
STOCHASTIC_KINDS = ("ProbabilityDistributionSet", "NormalDistribution", "LogNormalDistribution",
                    "UniformDistribution", "PoissonDistribution", "Histogram", "UserDefinedDistribution")


@dataclass(frozen=True)
class Variant:
    index: int            # 0-based position in the expansion
    name: str             # <stem>_<NNN>, NNN = index + 1
    parameters: tuple     # ((name, value), ...) in the distributions' document order

    @property
    def values(self):
        return dict(self.parameters)

    @property
    def label(self):
        return label(self.parameters)


@dataclass(frozen=True)
class Distribution:
    path: str             # the distribution file (absolute)
    scenario_file: str    # the scenario it varies (absolute)
    kind: str             # "deterministic" or "stochastic"
    seed: object          # the stochastic seed used (None for deterministic)
    variants: tuple       # Variant, ...


def label(parameters):
    """`name=value;...` of (name, value) pairs (numbers as %g with 10 digits)."""
    return ";".join("%s=%s" % (k, _text(v)) for k, v in parameters)


def _text(v):
    if isinstance(v, float):
        return "%.10g" % v
    return str(v)


# --- reading -----------------------------------------------------------------------------------

def _children(node, allowed):
    """node's children, each of a tag in allowed (else a ScenarioError naming it)."""
    for c in node.children:
        if c.tag not in allowed:
            raise c.error("is not supported in <%s> (supported here: %s)" % (
                node.tag, ", ".join("<%s>" % a for a in allowed) or "nothing"))
    return list(node.children)


def _attr(node, name):
    v = node.attrib.get(name)
    if v is None:
        raise node.error("needs attribute %s" % name)
    return v


def _number(node, name, default=None):
    raw = node.attrib.get(name)
    if raw is None:
        if default is not None:
            return default
        raise node.error("needs attribute %s" % name)
    if raw.strip().startswith("$"):
        raise node.error("%s: %r: a distribution file declares no parameters, give a number" % (name, raw))
    try:
        v = float(raw)
    except ValueError:
        raise node.error("%s: %r is not a number" % (name, raw)) from None
    if not math.isfinite(v):
        raise node.error("%s: %r is not a finite number" % (name, raw))
    return v


def _range(node):
    """(lower, upper) of a <Range> node."""
    lo, hi = _number(node, "lowerLimit"), _number(node, "upperLimit")
    if hi < lo:
        raise node.error("upperLimit %g is below lowerLimit %g" % (hi, lo))
    return lo, hi


def _optional_range(node):
    _children(node, ("Range",))
    r = node.find("Range")
    return _range(r) if r is not None else None


def _user_defined(node):
    return node.error("(type %r) is not supported: its meaning belongs to the tool that defines it; "
                      "use a DistributionSet, DistributionRange or a stochastic distribution"
                      % node.attrib.get("type", ""))


def is_distribution(path):
    """True when the file at path is an OpenSCENARIO ParameterValueDistribution file (a
    ScenarioError when it cannot be read or is not XML)."""
    root = parse_file(path)
    return any(c.tag == "ParameterValueDistribution" for c in root.children)


def expand(path, seed=0):
    """The Distribution of the file at path (module docstring)."""
    path = os.path.abspath(path)
    root = parse_file(path)
    if root.tag not in ("OpenSCENARIO", "OpenScenario"):
        raise root.error("is not an OpenSCENARIO file")
    pvd = root.find("ParameterValueDistribution")
    if pvd is None:
        raise root.error("holds no <ParameterValueDistribution>: not a parameter distribution file")
    _children(pvd, ("ScenarioFile", "Deterministic", "Stochastic"))
    scenario = _scenario_file(pvd, path)
    declared = _global_parameters(scenario, pvd.need("ScenarioFile"))
    kinds = [c for c in pvd.children if c.tag in ("Deterministic", "Stochastic")]
    if len(kinds) != 1:
        raise pvd.error("needs exactly one of <Deterministic>, <Stochastic>")
    node = kinds[0]
    if node.tag == "Deterministic":
        runs, used_seed = _deterministic(node), None
    else:
        runs, used_seed = _stochastic(node, seed)
    for params, where in runs:
        for k, _ in params:
            if k not in declared:
                raise where[k].error("%s: %s declares no global parameter %s (it declares: %s)" % (
                    "parameterRef" if where[k].tag == "ParameterAssignment" else "parameterName",
                    os.path.basename(scenario), k, ", ".join(declared) or "none"))
    stem = os.path.splitext(os.path.basename(path))[0]
    width = max(3, len(str(len(runs))))
    variants = tuple(Variant(i, "%s_%0*d" % (stem, width, i + 1), tuple(p))
                     for i, (p, _) in enumerate(runs))
    return Distribution(path, scenario, node.tag.lower(), used_seed, variants)


def _scenario_file(pvd, path):
    sf = pvd.need("ScenarioFile")
    raw = _attr(sf, "filepath")
    if not raw.strip():
        raise sf.error("filepath is empty")
    target = os.path.normpath(os.path.join(os.path.dirname(path), raw))
    if not os.path.isfile(target):
        raise sf.error("filepath: the scenario file %s does not exist" % target)
    return target


def _global_parameters(scenario, ref):
    """The names of the scenario's global parameters, in order; the scenario must be a
    scenario (not another distribution or a catalog)."""
    try:
        root = parse_file(scenario)
    except ScenarioError as e:
        raise ref.error("filepath: %s" % e) from None
    if root.find("Storyboard") is None:
        raise ref.error("filepath: %s is not a scenario (no <Storyboard>)" % os.path.basename(scenario))
    decls = root.find("ParameterDeclarations")
    return [d.attrib.get("name", "") for d in (decls.findall("ParameterDeclaration") if decls is not None else [])]


# --- deterministic -----------------------------------------------------------------------------

def _deterministic(node):
    """[(parameters [(name, value)], {name: node that sets it})] in expansion order."""
    axes = []   # each: [([(name, value)], {name: node})]
    owner = {}  # parameter -> the distribution node varying it
    for dist in _children(node, DETERMINISTIC):
        if dist.tag == "DeterministicSingleParameterDistribution":
            name = _attr(dist, "parameterName")
            choices = [[(name, v)] for v in _single(dist)]
            names = {name: dist}
        else:
            choices, names = _multi(dist)
        for k, n in names.items():
            if k in owner:
                raise n.error("parameter %s is varied already by <%s> at line %d" % (
                    k, owner[k].tag, owner[k].line))
            owner[k] = n
        axes.append([(c, names) for c in choices])
    if not axes:
        raise node.error("holds no distribution: nothing to expand")
    runs = []
    for combo in itertools.product(*axes):
        params, where = [], {}
        for choice, names in combo:
            params += choice
            where.update(names)
        runs.append((params, where))
    return runs


def _single(dist):
    kids = _children(dist, SINGLE_KINDS)
    if len(kids) != 1:
        raise dist.error("needs exactly one of <%s>" % ">, <".join(SINGLE_KINDS))
    k = kids[0]
    if k.tag == "UserDefinedDistribution":
        raise _user_defined(k)
    if k.tag == "DistributionSet":
        elems = _children(k, ("Element",))
        if not elems:
            raise k.error("needs at least one <Element>")
        return [_attr(e, "value") for e in elems]
    _children(k, ("Range",))
    step = _number(k, "stepWidth")
    if not step > 0:
        raise k.error("stepWidth: must be > 0, got %g" % step)
    lo, hi = _range(k.need("Range"))
    tol = 1e-9 * max(1.0, abs(lo), abs(hi))
    n = int(math.floor((hi - lo + tol) / step)) + 1
    if n > 100000:
        raise k.error("gives %d values (stepWidth %g over %g..%g): more than 100000" % (n, step, lo, hi))
    return [float("%.12g" % (lo + i * step)) for i in range(n)]


def _multi(dist):
    vsd_list = _children(dist, ("ValueSetDistribution",))
    if len(vsd_list) != 1:
        raise dist.error("needs exactly one <ValueSetDistribution>")
    sets = _children(vsd_list[0], ("ParameterValueSet",))
    if not sets:
        raise vsd_list[0].error("needs at least one <ParameterValueSet>")
    choices, names = [], {}
    for s in sets:
        assigns = _children(s, ("ParameterAssignment",))
        if not assigns:
            raise s.error("needs at least one <ParameterAssignment>")
        choice = []
        for a in assigns:
            k = _attr(a, "parameterRef")
            if any(k == n for n, _ in choice):
                raise a.error("parameterRef: %s is assigned twice in this <ParameterValueSet>" % k)
            choice.append((k, _attr(a, "value")))
            names.setdefault(k, a)
        choices.append(choice)
    return choices, names


# --- stochastic --------------------------------------------------------------------------------

def _seed_key(seed):
    """A random.Random seed of a number: an int when whole, else its repr (a str seed is
    hashed with SHA-512, stable across runs and Python versions)."""
    f = float(seed)
    return int(f) if f.is_integer() else repr(f)


def _stochastic(node, seed):
    raw_runs = node.attrib.get("numberOfTestRuns")
    runs_n = _number(node, "numberOfTestRuns")
    if not runs_n.is_integer() or runs_n < 1:
        raise node.error("numberOfTestRuns: must be a whole number >= 1, got %s" % raw_runs)
    if runs_n > 100000:
        raise node.error("numberOfTestRuns: %d is more than 100000" % runs_n)
    used = _number(node, "randomSeed") if "randomSeed" in node.attrib else seed
    dists = _children(node, ("StochasticDistribution",))
    if not dists:
        raise node.error("needs at least one <StochasticDistribution>")
    samplers, where = [], {}
    for d in dists:
        name = _attr(d, "parameterName")
        if name in where:
            raise d.error("parameterName: %s is varied already by the <StochasticDistribution> at line %d"
                          % (name, where[name].line))
        where[name] = d
        kids = _children(d, STOCHASTIC_KINDS)
        if len(kids) != 1:
            raise d.error("needs exactly one of <%s>" % ">, <".join(STOCHASTIC_KINDS))
        samplers.append((name, _sampler(kids[0])))
    rng = random.Random(_seed_key(used))
    out = []
    for _ in range(int(runs_n)):
        out.append(([(name, draw(rng)) for name, draw in samplers], dict(where)))
    return out, used


def _sampler(k):
    """A function rng -> value for the distribution node k."""
    if k.tag == "UserDefinedDistribution":
        raise _user_defined(k)
    if k.tag == "ProbabilityDistributionSet":
        elems = _children(k, ("Element",))
        if not elems:
            raise k.error("needs at least one <Element>")
        values = [_attr(e, "value") for e in elems]
        pick = _weighted(k, elems)
        return lambda rng: values[pick(rng)]
    if k.tag == "Histogram":
        bins = _children(k, ("Bin",))
        if not bins:
            raise k.error("needs at least one <Bin>")
        ranges = []
        for b in bins:
            _children(b, ("Range",))
            ranges.append(_range(b.need("Range")))
        pick = _weighted(k, bins)

        def histogram(rng):
            lo, hi = ranges[pick(rng)]
            return rng.uniform(lo, hi)
        return histogram
    if k.tag == "UniformDistribution":
        _children(k, ("Range",))
        lo, hi = _range(k.need("Range"))
        return lambda rng: rng.uniform(lo, hi)
    rng_range = _optional_range(k)
    mean = _number(k, "expectedValue")
    if k.tag == "PoissonDistribution":
        if not mean > 0:
            raise k.error("expectedValue: must be > 0, got %g" % mean)
        return _truncated(k, lambda rng: _poisson(rng, mean), rng_range)
    var = _number(k, "variance")
    if var < 0:
        raise k.error("variance: must be >= 0, got %g" % var)
    if k.tag == "NormalDistribution":
        sd = math.sqrt(var)
        return _truncated(k, lambda rng: rng.normalvariate(mean, sd), rng_range)
    if not mean > 0:
        raise k.error("expectedValue: must be > 0 for a log-normal distribution, got %g" % mean)
    s2 = math.log1p(var / (mean * mean))
    mu, s = math.log(mean) - s2 / 2.0, math.sqrt(s2)
    return _truncated(k, lambda rng: rng.lognormvariate(mu, s), rng_range)


def _weighted(node, items):
    """rng -> index of items, chosen by their weight attributes."""
    weights = []
    for it in items:
        w = _number(it, "weight")
        if w < 0:
            raise it.error("weight: must be >= 0, got %g" % w)
        weights.append(w)
    total = sum(weights)
    if not total > 0:
        raise node.error("the weights add up to 0")
    cum = list(itertools.accumulate(weights))

    def pick(rng):
        u = rng.random() * total
        for i, c in enumerate(cum):
            if u < c and weights[i] > 0:
                return i
        return max(i for i, w in enumerate(weights) if w > 0)
    return pick


def _truncated(node, draw, bounds):
    if bounds is None:
        return draw
    lo, hi = bounds

    def truncated(rng):
        for _ in range(MAX_REDRAWS):
            v = draw(rng)
            if lo <= v <= hi:
                return v
        raise node.error("its Range %g..%g holds too little of the distribution: no value in it "
                         "after %d draws" % (lo, hi, MAX_REDRAWS))
    return truncated


def _poisson(rng, lam):
    """A Poisson-distributed int: Knuth's multiplication for small means, else Hoermann's
    transformed rejection (PTRS, 1993)."""
    if lam < 30:
        limit, k, p = math.exp(-lam), 0, rng.random()
        while p > limit:
            k += 1
            p *= rng.random()
        return k
    slam, loglam = math.sqrt(lam), math.log(lam)
    b = 0.931 + 2.53 * slam
    a = -0.059 + 0.02483 * b
    inv_alpha = 1.1239 + 1.1328 / (b - 3.4)
    vr = 0.9277 - 3.6224 / (b - 2)
    while True:
        u = rng.random() - 0.5
        v = rng.random()
        us = 0.5 - abs(u)
        k = int(math.floor((2 * a / us + b) * u + lam + 0.43))
        if us >= 0.07 and v <= vr:
            return k
        if k < 0 or (us < 0.013 and v > us):
            continue
        if math.log(v * inv_alpha / (a / (us * us) + b)) <= -lam + k * loglam - math.lgamma(k + 1):
            return k


# --- command line ------------------------------------------------------------------------------

def main(argv=None):
    ap = argparse.ArgumentParser(
        prog="python3 -m convoy_scenario.distribution",
        description="Expands an OpenSCENARIO ParameterValueDistribution file: one line per variant "
                    "(the JSON of its parameters); the scenario file and the count on stderr.")
    ap.add_argument("file")
    ap.add_argument("--seed", type=int, default=0,
                    help="the seed of a stochastic distribution without randomSeed (default 0)")
    ap.add_argument("--names", action="store_true", help="prefix each line with the variant's name and a tab")
    a = ap.parse_args(argv)
    try:
        d = expand(a.file, a.seed)
    except ScenarioError as e:
        print("error: %s" % e, file=sys.stderr)
        return 2
    print("%s: %d variants of %s%s" % (os.path.basename(d.path), len(d.variants), d.scenario_file,
                                       "" if d.seed is None else " (seed %s)" % _text(d.seed)),
          file=sys.stderr)
    for v in d.variants:
        print(("%s\t" % v.name if a.names else "") + json.dumps(v.values))
    return 0


if __name__ == "__main__":
    sys.exit(main())
