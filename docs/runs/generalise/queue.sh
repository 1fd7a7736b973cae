#!/bin/sh
# The screening runs of docs/generalisation.md, one after another (one process at a time),
# in the order docs/runs/generalise/queue.txt lists them (read again after every run):
#   nohup setsid nice -n 10 sh docs/runs/generalise/queue.sh > /tmp/generalise.log 2>&1 &
# A run already finished (its .heldr.json exists) is skipped; an interrupted one resumes.
dir=docs/runs/generalise
while :; do
  name=$(while read -r n; do [ -f $dir/$n-seed1.heldr.json ] || { echo $n; break; }; done < $dir/queue.txt)
  [ -z "$name" ] && break
  echo "== $name $(date -u +%H:%M:%S)"
  sh $dir/run.sh $name 1 300 || { echo "!! $name failed"; break; }
done
echo "== done $(date -u +%H:%M:%S)"
