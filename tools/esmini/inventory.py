#!/usr/bin/python3
"""The element inventory of esmini's example scenarios (tests/data/esmini/xosc): every element
kind the scenario files and the catalog files they use contain, in how many scenario files,
and whether Convoy's reader schema (python/convoy_scenario/schema.py, SCHEMA) accepts it,
where it is refused (parent elements) and which of its attributes are outside the schema.
Writes tests/data/esmini/INVENTORY.md (or prints it with --print).

A scenario "uses" a catalog file when one of its CatalogReferences names that file's catalog
and the file lies in one of the scenario's CatalogLocations directories: the reader checks
whole catalog files, so every element of such a file counts.

    /usr/bin/python3 tools/esmini/inventory.py [--print] [--rev GIT_REV] [--before GIT_REV]

--rev takes the schema of a commit (git archive) instead of the working tree's; --before adds
a column with a commit's schema (the subset before a change).
"""

import argparse
import collections
import glob
import json
import os
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.normpath(os.path.join(HERE, "..", ".."))
XOSC_DIR = os.path.join(REPO, "tests", "data", "esmini", "xosc")
OUT = os.path.join(REPO, "tests", "data", "esmini", "INVENTORY.md")


def load(path):
    with open(path, "rb") as f:
        return ET.fromstring(f.read())


def catalog_files(root, xosc_dir, catalog_names):
    """Catalog files in the scenario's CatalogLocations whose Catalog name it references."""
    used = []
    locations = root.find("CatalogLocations")
    if locations is None:
        return used
    for directory in locations.iter("Directory"):
        d = os.path.normpath(os.path.join(xosc_dir, directory.get("path", "")))
        for path in sorted(glob.glob(os.path.join(d, "*.xosc"))):
            catalog = load(path).find("Catalog")
            if catalog is not None and catalog.get("name") in catalog_names and path not in used:
                used.append(path)
    return used


def walk(root, visit):
    """visit(parent tag or None, element) for every element."""
    stack = [(None, root)]
    while stack:
        parent, node = stack.pop()
        visit(parent, node)
        stack.extend((node.tag, child) for child in reversed(list(node)))


class Inventory:
    def __init__(self, schema):
        self.schema = schema
        self.own = collections.defaultdict(set)       # tag -> scenario files (own file)
        self.used = collections.defaultdict(set)      # tag -> scenario files (incl. catalogs)
        self.refused_in = collections.defaultdict(set)  # tag -> parents where refused
        self.bad_attrs = collections.defaultdict(set)   # tag -> attributes outside the schema

    def check(self, parent, node):
        entry = self.schema.get(node.tag)
        if entry is None or (parent is not None and
                             node.tag not in self.schema.get(parent, ((), ()))[1]):
            self.refused_in[node.tag].add(parent or "(root)")
        if entry is not None:
            for name in node.attrib:
                if node.tag == "OpenSCENARIO" and (":" in name or name.startswith("{")):
                    continue
                if name not in entry[0]:
                    self.bad_attrs[node.tag].add(name)

    def add_file(self, scenario, path, own):
        def visit(parent, node):
            self.used[node.tag].add(scenario)
            if own:
                self.own[node.tag].add(scenario)
            self.check(parent, node)
        walk(load(path), visit)

    def add_scenario(self, path):
        name = os.path.basename(path)
        root = load(path)
        self.add_file(name, path, own=True)
        refs = {r.get("catalogName") for r in root.iter("CatalogReference")}
        for cat in catalog_files(root, os.path.dirname(path), refs):
            self.add_file(name, cat, own=False)

    def accepted(self, tag):
        return tag in self.schema and not self.refused_in.get(tag)

    def table(self, total, where, before=None, before_where=""):
        """The markdown table; `before`: an Inventory of the same files under an earlier
        schema, shown as one more column."""
        tags = sorted(self.used, key=lambda t: (self.accepted(t), before.accepted(t) if before
                                                else True, -len(self.used[t]), t))
        refused = [t for t in tags if not self.accepted(t)]
        extra = " | accepted %s" % before_where if before else ""
        lines = [
            "# Element inventory of esmini's example scenarios", "",
            "Written by `tools/esmini/inventory.py` from the %d scenario files in `xosc/` and the "
            "catalog files they use, against python/convoy_scenario/schema.py's SCHEMA in %s "
            "(re-run it after schema changes). Accepted means the reader's schema check lets "
            "the element through, not that its semantics are implemented." % (total, where), "",
            "- files: scenario files using the element (in the file itself or in a catalog file "
            "it uses; own: in the file itself)",
            "- accepted: the schema has the element and allows it under every parent it has "
            "here; otherwise `refused under` names the parents where it is not allowed",
            "- attributes outside the schema: attributes used here that the schema does not "
            "list", "",
            "%d element kinds, %d not accepted (listed first, then those accepted now but not "
            "before), %d with attributes outside the schema."
            % (len(tags), len(refused), sum(1 for t in tags if self.bad_attrs.get(t)))]
        if before:
            lines.append("%s: %d not accepted, %d of them not in its SCHEMA." % (
                before_where[0].upper() + before_where[1:],
                sum(1 for t in tags if not before.accepted(t)),
                sum(1 for t in tags if t not in before.schema)))
        lines += ["", "| element | files | own | accepted | refused under | attributes outside "
                  "the schema%s |" % extra,
                  "|---|---:|---:|---|---|---|%s" % ("---|" if before else "")]
        for t in tags:
            lines.append("| %s | %d | %d | %s | %s | %s |%s" % (
                t, len(self.used[t]), len(self.own[t]), "yes" if self.accepted(t) else "no",
                ", ".join(sorted(self.refused_in.get(t, ()))) if t in self.schema else
                "(not in SCHEMA)",
                ", ".join(sorted(self.bad_attrs.get(t, ()))),
                (" %s |" % ("yes" if before.accepted(t) else "no")) if before else ""))
        return "\n".join(lines) + "\n"


def load_schema(rev):
    """SCHEMA of the working tree (rev None) or of a git revision, read in a child process
    (two versions of the package cannot share one)."""
    with tempfile.TemporaryDirectory(prefix="inventory-") as tmp:
        python_dir = os.path.join(REPO, "python")
        if rev:
            archive = subprocess.run(["git", "archive", rev, "python/convoy_scenario"],
                                     cwd=REPO, capture_output=True, check=True).stdout
            subprocess.run(["tar", "-x", "-C", tmp], input=archive, check=True)
            python_dir = os.path.join(tmp, "python")
        code = ("import json, sys; sys.path.insert(0, sys.argv[1]); "
                "from convoy_scenario import schema; print(json.dumps(schema.SCHEMA))")
        out = subprocess.run([sys.executable, "-c", code, python_dir], capture_output=True,
                             text=True, env=dict(os.environ, PYTHONDONTWRITEBYTECODE="1"))
        if out.returncode != 0:
            sys.exit("inventory: cannot read the schema of %s:\n%s" % (
                rev or "the working tree", out.stderr.strip()))
    return {tag: (tuple(attrs), tuple(children))
            for tag, (attrs, children) in json.loads(out.stdout).items()}


def inventory(schema, files):
    inv = Inventory(schema)
    for path in files:
        inv.add_scenario(path)
    return inv


def main():
    ap = argparse.ArgumentParser(description="esmini examples' element inventory")
    ap.add_argument("--xosc-dir", default=XOSC_DIR)
    ap.add_argument("--out", default=OUT)
    ap.add_argument("--print", action="store_true", help="print instead of writing")
    ap.add_argument("--rev", help="read the schema of this git revision")
    ap.add_argument("--before", metavar="REV",
                    help="add a column: accepted by the schema of this git revision")
    a = ap.parse_args()
    files = sorted(glob.glob(os.path.join(a.xosc_dir, "*.xosc")))
    inv = inventory(load_schema(a.rev), files)
    before = inventory(load_schema(a.before), files) if a.before else None
    text = inv.table(len(files), "commit %s" % a.rev if a.rev else "the working tree",
                     before, "before (commit %s)" % a.before if a.before else "")
    if a.print:
        sys.stdout.write(text)
    else:
        with open(a.out, "w") as f:
            f.write(text)
        print("wrote %s" % os.path.relpath(a.out))


if __name__ == "__main__":
    main()
