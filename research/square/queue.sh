#!/usr/bin/env bash
# Run the study's runs from a queue file, one per worker, workers sharing the file (research/square/README.md):
#   research/square/queue.sh QUEUE_FILE [WORKERS]     # each line: the arguments of `square.py run`, e.g. "80 10"
# A worker takes the first line (under flock), runs it, and takes the next; it stops when the file is empty.
# Lines can be appended or edited while the workers run.
set -u
queue=${1:?queue file}; workers=${2:-2}
cd "$(dirname "$0")/../.."
PY=${PYTHON:-/usr/bin/python3}
worker() {
  while :; do
    line=$(flock "$queue.lock" bash -c 'l=$(head -n 1 "$0"); [ -n "$l" ] && sed -i 1d "$0"; echo "$l"' "$queue")
    [ -z "$line" ] && return 0
    echo "$(date -u +%FT%TZ) worker $1 starts: $line"
    # shellcheck disable=SC2086
    $PY -m research.square.square run $line > "runs/square/log_$(echo $line | tr ' =/' '___').txt" 2>&1
    echo "$(date -u +%FT%TZ) worker $1 ends ($?): $line"
  done
}
mkdir -p runs/square
for w in $(seq 1 "$workers"); do worker "$w" & sleep 1; done
wait
