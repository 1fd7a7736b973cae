#!/bin/sh
# A candidate for the shipped generalising 4ws-5 controller (docs/generalisation.md, issue
# 21 item 5): recurrent networks (config/neat/4ws-recurrent.ini) on a generated-maze task,
# first 300 generations (written as NAME-seedS-g300.*: the run's screening row, comparable
# with ../run.sh's), then the same run continued to GENERATIONS (NAME-seedS.*), each
# evaluated on the three suites of evaluate.sh. Re-running the same command resumes from the
# checkpoint and skips what is done. SETTINGS, if given, is the run settings file
# (--config; select.yaml: snapshots and the balanced post-selection). The checkpoint is
# kept at the end, so that other post-selection rules can be tried on the finished run
# (selection-only settings may change on resume: docs/design.md section 13).
#   usage: sh docs/runs/generalise/ship/run.sh NAME TASK [SEED] [GENERATIONS] [SETTINGS]
#   e.g.   sh docs/runs/generalise/ship/run.sh 4ws-5-s6-p1 docs/runs/generalise/ship/task-s6-p1.yaml 1 1000 docs/runs/generalise/ship/select.yaml
# (Edit this file only by replacing it, never in place: a running sh reads it as it goes.)
set -e
name=$1; task=$2; seed=${3:-1}; gens=${4:-1000}; settings=${5:+--config $5}
dir=docs/runs/generalise/ship
out=$dir/$name-seed$seed
evolve() {
  .venv/bin/evorbc-evolve arbitrator --repertoire evorbc_ros/data/4ws-5.repertoire.json \
    --task $task --neat-config config/neat/4ws-recurrent.ini --seed $seed --workers 1 --quiet \
    $settings --checkpoint $out.checkpoint.json "$@"
}
if [ ! -f $out-g300.arbitrator.json ]; then
  evolve --generations 300 --keep-checkpoint --out $out-g300.arbitrator.json
fi
sh docs/runs/generalise/evaluate.sh $out-g300
if [ ! -f $out.arbitrator.json ] || [ -f $out.checkpoint.json ]; then
  evolve --generations $gens --keep-checkpoint --out $out.arbitrator.json
fi
sh docs/runs/generalise/evaluate.sh $out
