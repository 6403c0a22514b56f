"""A ParameterValueDistribution file read as one scenario: its ScenarioFile with the first
variant of its deterministic distributions (each single-parameter distribution's first
value: a set's first Element, a range's lowerLimit; a multi-parameter distribution's first
ParameterValueSet), as esmini runs such a file given as the scenario (permutation 0).
Expanding every variant is convoy_scenario's distribution module's job."""

import os

from .params import Scope, resolve
from .xmltree import ScenarioError


def first_variant(dist, path):
    """(absolute path of the ScenarioFile, [(parameter, value text)])."""
    sf = dist.need("ScenarioFile")
    rel = sf.attrib.get("filepath")
    if not rel:
        raise sf.error("needs attribute filepath")
    scenario = os.path.normpath(os.path.join(os.path.dirname(path), rel))
    if not os.path.isfile(scenario):
        raise sf.error("filepath: no such file %s" % scenario)
    values = []
    det = dist.find("Deterministic")
    for d in (det.children if det is not None else []):
        if d.tag == "DeterministicMultiParameterDistribution":
            sets = d.need("ValueSetDistribution").findall("ParameterValueSet")
            if not sets:
                raise d.error("needs at least one <ParameterValueSet>")
            for a in sets[0].findall("ParameterAssignment"):
                values.append((_attr(a, "parameterRef"), _attr(a, "value")))
            continue
        name = _attr(d, "parameterName")
        kind = d.only_child(("DistributionSet", "DistributionRange", "UserDefinedDistribution"))
        if kind.tag == "DistributionSet":
            elements = kind.findall("Element")
            if not elements:
                raise kind.error("needs at least one <Element>")
            values.append((name, _attr(elements[0], "value")))
        elif kind.tag == "DistributionRange":
            values.append((name, _attr(kind.need("Range"), "lowerLimit")))
        else:
            raise kind.error("is not supported (user-defined distributions)")
    return scenario, values


def _attr(node, name):
    raw = node.attrib.get(name)
    if raw is None:
        raise node.error("needs attribute %s" % name)
    try:
        return str(resolve(raw, Scope()))
    except Exception as e:  # a parameter reference: distributions have no parameters
        raise ScenarioError("%s: <%s> %s: %s" % (node.where(), node.tag, name, e)) from None
