#!/bin/sh
# The reduced-protocol studies of docs/study.md, one after another, one run at a time (each
# resumable: finished runs are skipped, an interrupted one resumes from its checkpoint):
#   nohup setsid nice -n 19 sh docs/study/runs/chain.sh >> /tmp/studies.log 2>&1 &
# It waits for a study runner already at work, then runs metrics and mappings (10 seeds) and
# bin-time (5 seeds), 300 generations each, and writes each study's report to docs/study/.
cd "$(dirname "$0")/../../.."
while pgrep -f "evorbc-study run" > /dev/null; do sleep 60; done
for spec in metrics:10 mappings:10 bin-time:5; do
  study=${spec%%:*}; seeds=${spec#*:}
  .venv/bin/evorbc-study run $study --results docs/study/runs/$study --seeds $seeds \
    --generations 300 --jobs 1 || exit 1
  .venv/bin/evorbc-study report $study --results docs/study/runs/$study --out docs/study || exit 1
done
