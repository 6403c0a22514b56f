"""A campaign's results: each task's outcome, its run's summary.json and its driving score,
merged into OUT/leaderboard.csv and OUT/results.json.

Per task (collect):
- the outcome from campaign.json: state, exit code, wall time, attempts, log, reason;
- "summary": the run folder's summary.json (the experiment's own fields, e.g. city_traffic's
  collisions, red_light_violations, min_ttc_s, autonomous_driving's detector_map50, and the
  coordinator's: sim_time_s, real_time_factor, ...), {} when missing or unreadable;
- "score": score_run(run_dir) of convoy_bench (the project's driving score, docs/scoring.md)
  for a run that exited 0, when that package is importable (convoy_bench.score.score_run, or
  convoy_bench.runs.score_run where it lives today); else None, with "score_error" saying
  why (the package is missing, or it could not score this run folder, e.g. a run without
  the ego's tracks.jsonl).

leaderboard.csv: one row per task, sorted by (scenario, seed, weather); columns COLUMNS:
scenario, seed, weather, parameters (a parameter distribution variant's values,
`name=value;...` in the distribution's order; empty for other entries), perception (the
reference agent's: "ground_truth" or "sensors", from the run's summary.json, else the
campaign's --perception; empty when neither says), driving_score,
route_completion, infraction_penalty (empty without a score), one count per infraction kind of INFRACTION_KINDS (the score's infractions with
"counted" not false; empty without a score), exit_code (empty when unknown), wall_s (3
decimals; empty when unknown). Numbers are written as Python's repr of the float, so the file
is the same byte for byte for the same runs, apart from wall_s.

results.json: the per-task records above, in the same order.
"""

import csv
import io
import json
import os

from . import atomic

INFRACTION_KINDS = ("collision_pedestrian", "collision_vehicle", "collision_static", "red_light",
                    "stop_sign", "scenario_timeout", "yield_emergency", "min_speed", "off_route",
                    "off_road", "wrong_way", "agent_blocked")
SCORE_COLUMNS = ("driving_score", "route_completion", "infraction_penalty")
COLUMNS = ("scenario", "seed", "weather", "parameters", "perception") + SCORE_COLUMNS + INFRACTION_KINDS + ("exit_code", "wall_s")


def load_scorer():
    """(score_run, None) when convoy_bench is importable, else (None, why not)."""
    try:
        from convoy_bench.score import score_run
    except ImportError:
        try:
            from convoy_bench.runs import score_run
        except ImportError as e:
            return None, "convoy_bench is not installed (%s)" % e
    return score_run, None


def _read_json(path):
    try:
        with open(path) as f:
            doc = json.load(f)
        return doc if isinstance(doc, dict) else {}
    except (OSError, ValueError):
        return {}


def infraction_counts(score):
    counts = {k: 0 for k in INFRACTION_KINDS}
    for inf in score.get("infractions") or []:
        if inf.get("counted", True) is not False and inf.get("kind") in counts:
            counts[inf["kind"]] += 1
    return counts


def collect(plan, state, scorer=None, scorer_missing=None):
    """The per-task records (module docstring), sorted by (scenario, seed, weather)."""
    records = []
    for task, st in zip(plan["tasks"], state.tasks):
        rec = {"name": task["name"], "scenario": task["scenario"], "seed": task["seed"],
               "weather": task["weather"], "parameters": task.get("parameters") or {},
               "perception": task.get("perception"), "config": task["config"], "run_dir": task["run_dir"],
               "state": st["state"], "exit_code": st["exit_code"], "wall_s": st["wall_s"],
               "attempts": st["attempts"], "log": st["log"], "reason": st["reason"],
               "summary": _read_json(os.path.join(task["run_dir"], "summary.json")),
               "score": None, "score_error": None}
        live = rec["summary"]
        if isinstance(live.get("perception"), str):
            rec["perception"] = live["perception"]   # what the run says it used
        if st["exit_code"] != 0:
            rec["score_error"] = "the run did not succeed"
        elif isinstance(live.get("score"), dict) and "driving_score" in live:
            # scored while it ran (a scenario run: convoy_bench/metrics_tf.py)
            rec["score"] = dict(live["score"], infractions=live.get("infractions") or [])
        elif scorer is None:
            rec["score_error"] = scorer_missing
        else:
            try:
                rec["score"] = scorer(task["run_dir"])
            except Exception as e:  # a run the scorer cannot read must not stop the campaign
                rec["score_error"] = "%s: %s" % (type(e).__name__, e)
        records.append(rec)
    records.sort(key=lambda r: (r["scenario"], r["seed"], r["weather"]))
    return records


def parameters_label(parameters):
    """`name=value;...` of a variant's parameters (numbers as %.10g), None without any."""
    if not parameters:
        return None
    return ";".join("%s=%s" % (k, "%.10g" % v if isinstance(v, float) else v)
                    for k, v in parameters.items())


def _cell(v):
    if v is None:
        return ""
    if isinstance(v, float):
        return repr(v)
    return str(v)


def leaderboard_rows(records):
    rows = []
    for r in records:
        row = {"scenario": r["scenario"], "seed": r["seed"], "weather": r["weather"],
               "parameters": parameters_label(r.get("parameters")), "perception": r.get("perception")}
        score = r["score"]
        for k in SCORE_COLUMNS:
            v = score.get(k) if score else None
            row[k] = float(v) if isinstance(v, (int, float)) else None
        counts = infraction_counts(score) if score else {}
        for k in INFRACTION_KINDS:
            row[k] = counts.get(k)
        row["exit_code"] = r["exit_code"]
        row["wall_s"] = "%.3f" % r["wall_s"] if r["wall_s"] is not None else None
        rows.append(row)
    return rows


def write(out_dir, records):
    """Writes leaderboard.csv and results.json into out_dir (each atomically: the old file or
    the new one, never half of one); returns their paths."""
    text = io.StringIO()
    w = csv.writer(text, lineterminator="\n")
    w.writerow(COLUMNS)
    for row in leaderboard_rows(records):
        w.writerow([_cell(row[c]) for c in COLUMNS])
    board = atomic.write_text(os.path.join(out_dir, "leaderboard.csv"), text.getvalue())
    results = atomic.write_json(os.path.join(out_dir, "results.json"), records, indent=1,
                                sort_keys=True, default=_json_default)
    return board, results


def _json_default(v):
    try:
        return float(v)  # numpy scalars from the scorer
    except (TypeError, ValueError):
        return str(v)
