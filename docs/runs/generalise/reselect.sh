#!/bin/sh
# Write a finished legged run's controller again under other selection settings (a
# second post-selection round, say: docs/design.md section 8), from a copy of its kept
# checkpoint, and evaluate it with run-legged.sh's suites. The first round's rows are in
# the checkpoint, so only new episodes run; the copy keeps them, so running again resumes.
#   usage: sh docs/runs/generalise/reselect.sh ROBOT RUN SETTINGS.yaml NAME [OWN]
#   e.g.   sh docs/runs/generalise/reselect.sh hexapod hexapod-t90-any \
#            docs/runs/generalise/tasks/hexapod-anywhere-f10.yaml hexapod-t90-any-f10 hexapod
# writes docs/runs/generalise/NAME-seed1.* (RUN's seed 1).
# (Edit this file only by replacing it, never in place: a running sh reads it as it goes.)
set -e
robot=$1; run=$2; settings=$3; name=$4; own=$5
dir=docs/runs/generalise
out=$dir/$name-seed1
[ -f $out.checkpoint.json ] || cp $dir/$run-seed1.checkpoint.json $out.checkpoint.json
if [ ! -f $out.arbitrator.json ]; then
  .venv/bin/evorbc-evolve arbitrator --repertoire evorbc_ros/data/$robot.repertoire.json \
    --config $settings --seed 1 --quiet --keep-checkpoint \
    --out $out.arbitrator.json --checkpoint $out.checkpoint.json
fi
sh $dir/run-legged.sh $robot $name 1 "" "" "" $own
