"""realism.json, realism.md and the PNGs of a realism run: per metric and source the
percentiles and mean, the Kolmogorov-Smirnov distances between the sources, rules of thumb
checked, and a verdict."""
import json
import os

import numpy as np

import metrics
import png_plot

SOURCES = ["pool", "sumo_idm", "sumo_krauss"]
COLOUR_NAMES = ["blue", "orange", "green"]
# metric: (unit, plot range lo, hi, tick, rule of thumb text, check(samples) -> (value, ok))
RULES = {
    "time_headway_s": ("s", 0, 6, 1, "median time gap of moving followers 1.0-2.5 s (urban)",
                       lambda x: (float(np.median(x)), 1.0 <= np.median(x) <= 2.5)),
    "speed_minus_limit_mps": ("m/s", -14, 6, 2, "under 10 % of moving samples more than "
                              "1.4 m/s (5 km/h) over the limit",
                              lambda x: (float(np.mean(x > 1.4)), np.mean(x > 1.4) < 0.1)),
    "acceleration_mps2": ("m/s^2", -5, 3, 1,
                          "decelerations harder than 3 m/s^2 in under 1 % of samples",
                          lambda x: (float(np.mean(x < -3)), np.mean(x < -3) < 0.01)),
    "jerk_mps3": ("m/s^3", -4, 4, 1, "|jerk| under 2 m/s^3 in at least 90 % of samples",
                  lambda x: (float(np.mean(np.abs(x) < 2)), np.mean(np.abs(x) < 2) >= 0.9)),
    "accepted_gap_s": ("s", 0, 30, 5, "p5 of the accepted gaps in crossing traffic at least 3 s",
                       lambda x: (float(np.percentile(x, 5)), np.percentile(x, 5) >= 3)),
}


def verdict(ks_pool_idm, ks_spread):
    if not np.isfinite(ks_pool_idm):
        return "no samples"
    word = "close" if ks_pool_idm <= 0.1 else "similar" if ks_pool_idm <= 0.25 else "different"
    within = "within" if ks_pool_idm <= ks_spread else "beyond"
    return "%s to SUMO-IDM (KS %.2f, %s the two SUMO models' spread %.2f)" % (
        word, ks_pool_idm, within, ks_spread)


def _check(name, x):
    if len(x) == 0:
        return None, False
    value, ok = RULES[name][5](x)
    return value, bool(ok)


def write(folder, setup, results):
    doc = {"setup": setup, "metrics": {}, "flows_vph": {}}
    for name in RULES:
        entry = {"unit": RULES[name][0], "rule_of_thumb": RULES[name][4], "sources": {}}
        for src in SOURCES:
            x = results[src][0][name]
            entry["sources"][src] = metrics.summary(x)
        a, b, c = (results[s][0][name] for s in SOURCES)
        ks = entry["ks"] = {"pool_vs_sumo_idm": metrics.ks(a, b),
                            "pool_vs_sumo_krauss": metrics.ks(a, c),
                            "sumo_idm_vs_sumo_krauss": metrics.ks(b, c)}
        entry["verdict"] = verdict(ks["pool_vs_sumo_idm"], ks["sumo_idm_vs_sumo_krauss"])
        doc["metrics"][name] = entry
        png_plot.histograms(os.path.join(folder, name + ".png"), [a, b, c], *RULES[name][1:4])
    for src in SOURCES:
        for name in RULES:
            x = results[src][0][name]
            value, ok = _check(name, x)
            doc["metrics"][name]["sources"][src]["rule_value"] = value
            doc["metrics"][name]["sources"][src]["rule_ok"] = ok
    doc["flows_vph"] = _flows(results)
    with open(os.path.join(folder, "realism.json"), "w") as f:
        json.dump(doc, f, indent=1, default=float)
    with open(os.path.join(folder, "realism.md"), "w") as f:
        f.write(markdown(doc))
    return doc


def _flows(results):
    """Vehicles/h at the measuring points: the 6 roads busiest over all sources."""
    per = {src: results[src][1] for src in SOURCES}
    roads = sorted({r for f in per.values() for r in f},
                   key=lambda r: -sum(per[s].get(r, 0) for s in SOURCES))[:6]
    return {r: {s: per[s].get(r, 0.0) for s in SOURCES} for r in roads}


def text_table(doc):
    lines = []
    for name, e in doc["metrics"].items():
        lines.append("%s (%s): %s" % (name, e["unit"], e["verdict"]))
        for src in SOURCES:
            s = e["sources"][src]
            if s["n"] == 0:
                lines.append("  %-12s n 0" % src)
                continue
            lines.append("  %-12s n %7d  p5 %7.2f p25 %7.2f p50 %7.2f p75 %7.2f p95 %7.2f "
                         "mean %7.2f  rule %s (%.3g)" % (
                             src, s["n"], s["p5"], s["p25"], s["p50"], s["p75"], s["p95"],
                             s["mean"], "ok" if s["rule_ok"] else "NOT met", s["rule_value"]))
    lines.append("flow, vehicles/h (both directions, distinct vehicles on the road):")
    for road, f in doc["flows_vph"].items():
        lines.append("  road %-6s " % road + "  ".join("%s %6.0f" % (s, f[s]) for s in SOURCES))
    return "\n".join(lines)


def markdown(doc):
    st = doc["setup"]
    out = ["# Realism: the pool against SUMO", "",
           "Map `%s`, %d flows of %g vehicles/h, %g s warm-up, %g s traced at %g s; pool dt %g s, "
           "SUMO step %g s; seed %d; %s, load average %s." % (
               st["map"], st["flows"], st["rate_per_flow"], st["warmup_s"], st["seconds"],
               st["sample_s"], st["pool_dt"], st["sumo_dt"], st["seed"], st["date"],
               ", ".join("%.1f" % v for v in st["load_average"])), ""]
    for src, r in st["runs"].items():
        out.append("- %s: %s (wall %.1f s)" % (src, r["summary"], r["wall_s"]))
    out += ["", "Plots: %s lines = %s; x from the table's range, ticks as given." % (
        ", ".join(COLOUR_NAMES), ", ".join(SOURCES)), ""]
    for name, e in doc["metrics"].items():
        lo, hi, tick = RULES[name][1:4]
        out += ["## %s (%s)" % (name, e["unit"]), "", "Verdict: %s. Rule of thumb: %s." % (
            e["verdict"], e["rule_of_thumb"]), "",
            "| source | n | p5 | p25 | p50 | p75 | p95 | mean | rule value | rule met |",
            "|---|---|---|---|---|---|---|---|---|---|"]
        for src in SOURCES:
            s = e["sources"][src]
            if s["n"] == 0:
                out.append("| %s | 0 | | | | | | | | no |" % src)
                continue
            out.append("| %s | %d | %.2f | %.2f | %.2f | %.2f | %.2f | %.2f | %.3g | %s |" % (
                src, s["n"], s["p5"], s["p25"], s["p50"], s["p75"], s["p95"], s["mean"],
                s["rule_value"], "yes" if s["rule_ok"] else "no"))
        out += ["", "KS: " + ", ".join("%s %.3f" % kv for kv in e["ks"].items()), "",
                "![%s](%s.png) (x %g to %g, tick %g)" % (name, name, lo, hi, tick), ""]
    out += ["## Flow (vehicles/h on a road, both directions)", "",
            "| road | " + " | ".join(SOURCES) + " |", "|---|" + "---|" * len(SOURCES)]
    for road, f in doc["flows_vph"].items():
        out.append("| %s | " % road + " | ".join("%.0f" % f[s] for s in SOURCES) + " |")
    return "\n".join(out) + "\n"
