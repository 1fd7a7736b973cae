#!/bin/sh
# One legged screening run of docs/generalisation.md: evolve ROBOT's arbitrator on a task of
# tasks/ with its shipped repertoire, then evaluate it from 20 random starts in its own maze
# and on the 10 held-out mazes (seed 21021) x 20 starts (issue 21 item 5), unperturbed and
# under `realistic`, with the episodes it was trained with, and from 100 starts in its own
# maze (NAME-seedS.own100.json: 20 starts leave a reach rate within about +-19 points;
# docs/generalisation.md, "The hexapod"). OWN names the own-maze suite when the task trains
# on more (e.g. `hexapod` for a task that adds tasks/hexapod-anywhere.yaml, whose starts
# are not the ones the issue measures); by default the task's mazes. Re-running the same
# command resumes from the checkpoint; the checkpoint is kept at the end, so that another
# post-selection rule can be tried on the finished run (delete NAME-seedS.arbitrator.json
# and run again with other SETTINGS: docs/design.md section 13).
# INIT starts the run from that arbitrator file's network (`--init-from`, docs/design.md
# section 8) instead of random networks.
#   usage: sh docs/runs/generalise/run-legged.sh ROBOT NAME [SEED] [GENERATIONS] [NEAT.ini] [SETTINGS.yaml] [OWN] [INIT]
#   e.g.   sh docs/runs/generalise/run-legged.sh hexapod hexapod-t90-s2 1 200 \
#            docs/runs/generalise/tasks/hexapod-pop100.ini docs/runs/generalise/tasks/hexapod-reach.yaml
# (Edit this file only by replacing it, never in place: a running sh reads it as it goes.)
set -e
robot=$1; name=$2; seed=${3:-1}; gens=${4:-200}; neat=${5:+--neat-config $5}; settings=${6:+--config $6}
own=${7:+--mazes $7}; init=${8:+--init-from $8}
dir=docs/runs/generalise
out=$dir/$name-seed$seed
if [ ! -f $out.arbitrator.json ]; then
  .venv/bin/evorbc-evolve arbitrator --repertoire evorbc_ros/data/$robot.repertoire.json \
    --task $dir/tasks/$name.yaml --seed $seed --generations $gens --quiet $neat $settings $init \
    --keep-checkpoint --out $out.arbitrator.json --checkpoint $out.checkpoint.json
fi
for suite in own held ownr heldr own100; do
  [ -f $out.$suite.json ] && continue
  case $suite in
    own) extra="$own --starts 20 --perturb none" ;;
    held) extra="--generated 10 --starts 20 --perturb none" ;;
    ownr) extra="$own --starts 20 --perturb realistic" ;;
    heldr) extra="--generated 10 --starts 20 --perturb realistic" ;;
    own100) extra="$own --starts 100 --perturb none" ;;
  esac
  .venv/bin/evorbc-evolve evaluate --arbitrator $out.arbitrator.json $extra \
    --repertoire evorbc_ros/data/$robot.repertoire.json --json | .venv/bin/python $dir/summary.py > $out.$suite.tmp
  mv $out.$suite.tmp $out.$suite.json
done
