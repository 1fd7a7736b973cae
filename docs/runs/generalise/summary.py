"""Keep an `evorbc-evolve evaluate --json` report's figures, not its episodes (stdin to stdout)."""

import json
import sys

report = json.load(sys.stdin)
report.pop("episodes")
json.dump(report, sys.stdout, indent=1)
print()
