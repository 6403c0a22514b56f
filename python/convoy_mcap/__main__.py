"""python3 -m convoy_mcap FILE.mcap: checks a recording and lists its topics and metadata."""
import json
import sys
import warnings

from .reader import McapError, McapIncompleteWarning, Recording


def main(argv):
    if len(argv) != 1:
        print("usage: python3 -m convoy_mcap FILE.mcap", file=sys.stderr)
        return 2
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", McapIncompleteWarning)
            rec = Recording(argv[0])
    except (McapError, OSError) as e:
        print("error: %s" % e, file=sys.stderr)
        return 2
    counts = {}
    for m in rec.messages():
        counts[m.topic] = counts.get(m.topic, 0) + 1
    if not rec.complete:
        print("warning: %s: incomplete recording: %s; read its %d messages up to there"
              % (argv[0], rec.incomplete, sum(counts.values())), file=sys.stderr)
    print(json.dumps({"complete": rec.complete, "incomplete": rec.incomplete,
                      "library": rec.library, "records": rec.records,
                      "messages": sum(counts.values()), "topics": counts,
                      "metadata": {k: {kk: vv for kk, vv in v.items() if kk != "config"}
                                   for k, v in rec.metadata.items()}}, indent=2))
    return 0


sys.exit(main(sys.argv[1:]))
