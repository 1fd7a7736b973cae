#!/bin/sh
# The screening runs of docs/generalisation.md, one after another (one process at a time),
# in the order docs/runs/generalise/queue.txt lists them (read again after every run). A
# line is NAME, or NAME NEAT_INI for a run with other NEAT settings (run.sh's 4th argument):
#   nohup setsid nice -n 10 sh docs/runs/generalise/queue.sh > /tmp/generalise.log 2>&1 &
# A run already finished (its .heldr.json exists) is skipped; an interrupted one resumes.
# (Edit this file and run.sh only by replacing them, never in place: a running sh reads them
# as it goes. queue.txt may be edited at any time.)
dir=docs/runs/generalise
while :; do
  line=$(while read -r n ini; do [ -f $dir/$n-seed1.heldr.json ] || { echo "$n $ini"; break; }; done < $dir/queue.txt)
  set -- $line
  [ -z "$1" ] && break
  echo "== $1 $(date -u +%H:%M:%S)"
  sh $dir/run.sh $1 1 300 $2 || { echo "!! $1 failed"; break; }
done
echo "== done $(date -u +%H:%M:%S)"
