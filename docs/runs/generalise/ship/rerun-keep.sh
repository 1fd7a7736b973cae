#!/bin/sh
# Run (or rerun) a ship candidate to GENERATIONS with its checkpoint kept at the end, so
# that other post-selection rules can be tried on the same run later (selection-only
# settings may change on resume: docs/design.md section 13). The evolution is seeded: a
# rerun repeats the original run exactly, and only the written controller can differ.
#   usage: sh docs/runs/generalise/ship/rerun-keep.sh NAME TASK SEED GENERATIONS SETTINGS
#   e.g.   sh docs/runs/generalise/ship/rerun-keep.sh 4ws-5-p8-p1-ntb docs/runs/generalise/ship/task-p8-p1.yaml 1 1000 docs/runs/generalise/ship/select-ntb.yaml
# (Edit this file only by replacing it, never in place: a running sh reads it as it goes.)
set -e
name=$1; task=$2; seed=$3; gens=$4; settings=$5
out=docs/runs/generalise/ship/$name-seed$seed
if [ ! -f $out.arbitrator.json ]; then
  .venv/bin/evorbc-evolve arbitrator --repertoire evorbc_ros/data/4ws-5.repertoire.json \
    --task $task --neat-config config/neat/4ws-recurrent.ini --seed $seed --workers 1 --quiet \
    --config $settings --checkpoint $out.checkpoint.json --keep-checkpoint \
    --generations $gens --out $out.arbitrator.json
fi
sh docs/runs/generalise/evaluate.sh $out
