"""OUT/report.html: one static page of a campaign's results that opens offline (no scripts, no
external fonts or images; the plots are inline SVG written here).

Sections, from results.collect's records:
1. Overview: tasks, done, failed, seeds, weathers, where the scores come from.
2. Driving score per scenario: a bar per scenario at the mean driving score (DS, 0-100) of its
   scored runs, a whisker from the lowest to the highest seed mean (each seed's DS averaged
   over the weathers) and a dot per run. Without any score, a sentence saying why.
3. Infractions: per scenario, the score's counted infractions by kind, per km of route where
   every scored run of the scenario knows its route length ("route_length_m": count / sum of
   the route lengths), else per run; a bar chart of the total. Without scores, the runs'
   own summary.json counts (collisions, red_light_violations) per run, so labelled.
4. DS spread across seeds: per scenario and weather, the mean, min, max and population
   standard deviation of DS over the seeds.
5. A table per scenario (under its scenario file, and a distribution variant's parameters):
   one row per task (seed, weather, DS, RC, penalty, infractions,
   collisions, red-light violations, min TTC, detector mAP@0.5, simulated s, exit code,
   attempts, wall s).
6. Failed tasks: exit code, reason, log path and the last LOG_TAIL_LINES lines of its log.
Every value from the runs is HTML-escaped.

A run that has a recording (RUN_DIR/recording.mcap) links to it in the web dashboard
(`/?mcap=/files/<run path relative to the campaign folder>/recording.mcap`): those links work
when `convoy view CAMPAIGN_DIR` serves this page (the line at the top says so).
"""

import html
import math
import os
import urllib.parse

from . import atomic
from .results import INFRACTION_KINDS, infraction_counts, parameters_label

LOG_TAIL_LINES = 40
CSS = """
body{font-family:sans-serif;margin:1.5em;color:#222;max-width:1100px}
table{border-collapse:collapse;margin:.5em 0 1.5em}
td,th{border:1px solid #ccc;padding:2px 7px;text-align:right;font-size:13px}
th{background:#eee}td:first-child,th:first-child{text-align:left}
tr.failed td{background:#fdd}
pre{background:#f6f6f6;border:1px solid #ddd;padding:6px;font-size:12px;overflow-x:auto}
.note{color:#666;font-size:13px}
"""


def _e(v):
    return html.escape(str(v), quote=True)


def _fmt(v, digits=2):
    if v is None:
        return "&mdash;"
    if isinstance(v, bool):
        return "yes" if v else "no"
    if isinstance(v, float):
        return "%.*f" % (digits, v)
    return _e(v)


def _mean(xs):
    return math.fsum(xs) / len(xs) if xs else None


def _stdev(xs):
    if not xs:
        return None
    m = _mean(xs)
    return math.sqrt(math.fsum((x - m) ** 2 for x in xs) / len(xs))


def _ds(r):
    v = (r["score"] or {}).get("driving_score")
    return float(v) if isinstance(v, (int, float)) else None


def bar_chart(items, y_max, y_label, width=720):
    """Inline SVG: items [(label, value, low, high, points)] as vertical bars with whiskers
    from low to high and dots at points; None values are drawn as "n/a"."""
    height, left, bottom, top = 260, 56, 70, 16
    plot_w, plot_h = width - left - 10, height - bottom - top
    n = max(len(items), 1)
    slot = plot_w / n
    y = lambda v: top + plot_h * (1.0 - (v / y_max if y_max > 0 else 0.0))
    parts = ['<svg xmlns="http://www.w3.org/2000/svg" width="%d" height="%d" '
             'font-family="sans-serif" font-size="11">' % (width, height)]
    for k in range(5):
        v = y_max * k / 4
        parts.append('<line x1="%d" x2="%d" y1="%.1f" y2="%.1f" stroke="#ddd"/>'
                     '<text x="%d" y="%.1f" text-anchor="end">%s</text>' % (
                         left, width - 10, y(v), y(v), left - 4, y(v) + 4, _fmt_num(v)))
    parts.append('<text x="12" y="%d" transform="rotate(-90 12 %d)" text-anchor="middle">%s</text>'
                 % (top + plot_h // 2, top + plot_h // 2, _e(y_label)))
    for i, (label, value, low, high, points) in enumerate(items):
        cx = left + slot * (i + 0.5)
        bw = min(60.0, slot * 0.6)
        if value is None:
            parts.append('<text x="%.1f" y="%.1f" text-anchor="middle" fill="#999">n/a</text>'
                         % (cx, top + plot_h - 4))
        else:
            parts.append('<rect x="%.1f" y="%.1f" width="%.1f" height="%.1f" fill="#6a9fd4">'
                         '<title>%s: %s</title></rect>' % (
                             cx - bw / 2, y(value), bw, max(0.0, top + plot_h - y(value)),
                             _e(label), _fmt_num(value)))
            if low is not None and high is not None:
                parts.append('<line x1="%.1f" x2="%.1f" y1="%.1f" y2="%.1f" stroke="#222"/>'
                             '<line x1="%.1f" x2="%.1f" y1="%.1f" y2="%.1f" stroke="#222"/>'
                             '<line x1="%.1f" x2="%.1f" y1="%.1f" y2="%.1f" stroke="#222"/>' % (
                                 cx, cx, y(low), y(high), cx - 6, cx + 6, y(low), y(low),
                                 cx - 6, cx + 6, y(high), y(high)))
            for p in points:
                parts.append('<circle cx="%.1f" cy="%.1f" r="2.5" fill="#c0392b"/>' % (cx + bw / 4, y(p)))
        parts.append('<text x="%.1f" y="%d" text-anchor="end" transform="rotate(-35 %.1f %d)">%s</text>'
                     % (cx, top + plot_h + 14, cx, top + plot_h + 14, _e(label)))
    parts.append('<line x1="%d" x2="%d" y1="%d" y2="%d" stroke="#444"/></svg>' % (
        left, width - 10, top + plot_h, top + plot_h))
    return "".join(parts)


def _fmt_num(v):
    return ("%.0f" % v) if abs(v) >= 10 or v == 0 else ("%.2g" % v)


def _nice_max(v):
    if v <= 0:
        return 1.0
    mag = 10 ** math.floor(math.log10(v))
    for m in (1, 2, 2.5, 5, 10):
        if v <= m * mag:
            return m * mag
    return 10 * mag


def _count(v):
    if isinstance(v, list):
        return len(v)
    return v if isinstance(v, (int, float)) and not isinstance(v, bool) else None


def recording_link(record, out_dir):
    """The dashboard URL of the run's recording as `convoy view OUT_DIR` serves it, or None
    when the run has no recording.mcap (or lies outside the campaign folder)."""
    run_dir = record.get("run_dir")
    if not run_dir or not os.path.isfile(os.path.join(run_dir, "recording.mcap")):
        return None
    rel = os.path.relpath(os.path.abspath(run_dir), os.path.abspath(out_dir))
    if rel == ".." or rel.startswith(".." + os.sep) or os.path.isabs(rel):
        return None
    path = "/".join(p for p in rel.split(os.sep) if p not in ("", "."))
    return "/?mcap=/files/%s" % urllib.parse.quote(
        (path + "/" if path else "") + "recording.mcap")


def render(records, plan, scorer_missing=None):
    by_scenario = {}
    for r in records:
        by_scenario.setdefault(r["scenario"], []).append(r)
    failed = [r for r in records if r["state"] != "done"]
    out = ['<!DOCTYPE html><html><head><meta charset="utf-8"><title>Convoy campaign</title>'
           '<style>%s</style></head><body>' % CSS]
    out.append("<h1>Convoy campaign</h1>")
    links = {id(r): recording_link(r, plan["out"]) for r in records}
    recorded = any(links.values())
    if recorded:
        out.append('<p class="note">Recordings: open with <code>convoy view CAMPAIGN_DIR</code> '
                   '(here <code>convoy view %s</code>) and follow a run\'s '
                   '&ldquo;view&rdquo; link to watch it in the dashboard.</p>' % _e(plan["out"]))
    out.append("<p>%d tasks (%d scenarios &times; %d seeds &times; %d weathers: %s): "
               "%d done, %d failed. Output: <code>%s</code>.</p>" % (
                   len(records), len(by_scenario), plan["seeds"], len(plan["weathers"]),
                   _e(", ".join(plan["weathers"])), len(records) - len(failed), len(failed),
                   _e(plan["out"])))
    scored = [r for r in records if _ds(r) is not None]
    if scorer_missing:
        out.append('<p class="note">No driving scores: %s.</p>' % _e(scorer_missing))
    elif not scored:
        out.append('<p class="note">No run could be scored (see the score errors in '
                   'results.json).</p>')

    # 2. DS per scenario
    out.append("<h2>Driving score per scenario</h2>")
    if scored:
        items = []
        for name, rs in by_scenario.items():
            ds = [_ds(r) for r in rs if _ds(r) is not None]
            seeds = {}
            for r in rs:
                if _ds(r) is not None:
                    seeds.setdefault(r["seed"], []).append(_ds(r))
            seed_means = [_mean(v) for v in seeds.values()]
            items.append((name, _mean(ds), min(seed_means) if seed_means else None,
                          max(seed_means) if seed_means else None, ds))
        out.append(bar_chart(items, 100.0, "driving score"))
        out.append('<p class="note">Bar: mean DS over the scenario\'s runs; whisker: lowest to '
                   'highest seed mean; dots: the runs.</p>')
    else:
        out.append('<p class="note">No driving scores to plot.</p>')

    # 3. infractions
    out.append("<h2>Infractions</h2>")
    if scored:
        out.append(_infraction_table(by_scenario))
    else:
        out.append(_summary_infraction_table(by_scenario))

    # 4. spread
    out.append("<h2>DS spread across seeds</h2>")
    if scored:
        out.append("<table><tr><th>scenario</th><th>weather</th><th>seeds</th><th>mean</th>"
                   "<th>min</th><th>max</th><th>std</th></tr>")
        for name, rs in by_scenario.items():
            for w in plan["weathers"]:
                ds = [_ds(r) for r in rs if r["weather"] == w and _ds(r) is not None]
                out.append("<tr><td>%s</td><td>%s</td><td>%d</td><td>%s</td><td>%s</td><td>%s</td>"
                           "<td>%s</td></tr>" % (_e(name), _e(w), len(ds), _fmt(_mean(ds)),
                                                 _fmt(min(ds) if ds else None),
                                                 _fmt(max(ds) if ds else None), _fmt(_stdev(ds))))
        out.append("</table>")
    else:
        out.append('<p class="note">No driving scores.</p>')

    # 5. per scenario
    for name, rs in by_scenario.items():
        out.append('<h2 id="%s">%s</h2>' % (_e(name), _e(name)))
        params = parameters_label(rs[0].get("parameters"))
        out.append('<p class="note">%s%s</p>' % (_e(rs[0]["config"]), " with %s" % _e(params) if params else ""))
        out.append("<table><tr><th>seed</th><th>weather</th><th>DS</th><th>RC</th><th>penalty</th>"
                   "<th>infractions</th><th>collisions</th><th>red lights</th><th>min TTC s</th>"
                   "<th>mAP@0.5</th><th>sim s</th><th>exit</th><th>attempts</th><th>wall s</th>%s"
                   "</tr>" % ("<th>recording</th>" if recorded else ""))
        for r in rs:
            s, sc = r["summary"], r["score"] or {}
            infr = sum(infraction_counts(sc).values()) if r["score"] else None
            out.append('<tr%s><td>%d</td><td>%s</td><td>%s</td><td>%s</td><td>%s</td><td>%s</td>'
                       "<td>%s</td><td>%s</td><td>%s</td><td>%s</td><td>%s</td><td>%s</td>"
                       "<td>%d</td><td>%s</td></tr>" % (
                           ' class="failed"' if r["state"] != "done" else "", r["seed"],
                           _e(r["weather"]), _fmt(sc.get("driving_score")),
                           _fmt(sc.get("route_completion")), _fmt(sc.get("infraction_penalty"), 3),
                           _fmt(infr), _fmt(_count(s.get("collisions"))),
                           _fmt(_count(s.get("red_light_violations"))), _fmt(s.get("min_ttc_s")),
                           _fmt(s.get("detector_map50"), 3), _fmt(s.get("sim_time_s")),
                           _fmt(r["exit_code"]), r["attempts"], _fmt(r["wall_s"], 1)))
            if recorded:
                link = links[id(r)]
                out[-1] = out[-1][:-len("</tr>")] + "<td>%s</td></tr>" % (
                    '<a href="%s">view</a>' % _e(link) if link else "&mdash;")
        out.append("</table>")

    # 6. failed
    out.append("<h2>Failed tasks</h2>")
    if not failed:
        out.append("<p>None.</p>")
    for r in failed:
        out.append("<h3>%s</h3><p>exit code %s%s; %d attempt(s); log <code>%s</code></p>" % (
            _e(r["name"]), _fmt(r["exit_code"]), "; " + _e(r["reason"]) if r["reason"] else "",
            r["attempts"], _e(r["log"])))
        out.append("<pre>%s</pre>" % _e(_tail(r["log"])))
    out.append("</body></html>\n")
    return "\n".join(out)


def _infraction_table(by_scenario):
    rows, items = [], []
    for name, rs in by_scenario.items():
        scored = [r for r in rs if r["score"]]
        totals = {k: 0 for k in INFRACTION_KINDS}
        for r in scored:
            for k, v in infraction_counts(r["score"]).items():
                totals[k] += v
        lengths = [r["score"].get("route_length_m") for r in scored]
        per_km = bool(scored) and all(isinstance(v, (int, float)) and v > 0 for v in lengths)
        denom = math.fsum(lengths) / 1000.0 if per_km else float(len(scored) or 1)
        unit = "per km" if per_km else "per run"
        rows.append((name, unit, len(scored), {k: totals[k] / denom for k in INFRACTION_KINDS}))
        items.append(("%s (%s)" % (name, unit), sum(totals.values()) / denom if scored else None,
                      None, None, []))
    kinds = [k for k in INFRACTION_KINDS if any(row[3][k] for row in rows)] or ["collision_vehicle"]
    out = [bar_chart(items, _nice_max(max([v for _, v, _, _, _ in items if v is not None] or [0])),
                     "infractions")]
    out.append("<table><tr><th>scenario</th><th>unit</th><th>scored runs</th>%s</tr>" % "".join(
        "<th>%s</th>" % _e(k) for k in kinds))
    for name, unit, n, rates in rows:
        out.append("<tr><td>%s</td><td>%s</td><td>%d</td>%s</tr>" % (
            _e(name), unit, n, "".join("<td>%s</td>" % _fmt(rates[k], 3) for k in kinds)))
    out.append("</table>")
    return "\n".join(out)


def _summary_infraction_table(by_scenario):
    out = ['<p class="note">Without driving scores: the runs\' own summary.json counts, per '
           'run (runs that wrote them).</p>',
           "<table><tr><th>scenario</th><th>runs</th><th>collisions per run</th>"
           "<th>red-light violations per run</th></tr>"]
    for name, rs in by_scenario.items():
        col = [_count(r["summary"].get("collisions")) for r in rs]
        red = [_count(r["summary"].get("red_light_violations")) for r in rs]
        col = [c for c in col if c is not None]
        red = [c for c in red if c is not None]
        out.append("<tr><td>%s</td><td>%d</td><td>%s</td><td>%s</td></tr>" % (
            _e(name), len(rs), _fmt(_mean(col)), _fmt(_mean(red))))
    out.append("</table>")
    return "\n".join(out)


def _tail(path, lines=LOG_TAIL_LINES):
    try:
        with open(path, errors="replace") as f:
            text = f.read().splitlines()
    except OSError as e:
        return "(no log: %s)" % e.strerror
    return "\n".join(text[-lines:])


def write(out_dir, records, plan, scorer_missing=None):
    return atomic.write_text(os.path.join(out_dir, "report.html"),
                             render(records, plan, scorer_missing))
