#!/bin/sh
# Runs `evfs video` over N MPI ranks on this machine: rank 0 hands out the windows and writes
# the output, the other ranks solve them (app/video_mpi.h). Every argument after N goes to evfs.
#   scripts/evfs-video-mpi.sh 4 --data=DIR --out=OUT --fps=240
# On a cluster, use srun instead (docs/guide.md, `evfs video`). The output is the same as with
# one process.
set -eu
if [ "$#" -lt 2 ]; then
  echo "usage: $0 RANKS --data=DIR --out=OUT [evfs video flags]" >&2
  exit 2
fi
ranks=$1
shift
evfs=${EVFS:-$(dirname "$0")/../build/examples/evfs}
# Root in a container needs --allow-run-as-root; more ranks than cores need --oversubscribe.
exec mpirun --allow-run-as-root --oversubscribe -np "$ranks" "$evfs" video "$@"
