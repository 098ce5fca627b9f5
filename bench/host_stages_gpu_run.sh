#!/bin/bash
# On the GPU machine (carry .gl and .replay; .replay/host_stages.txz from bench/host_stages_gpu_pack.sh):
# exitance-relight of the building at 12 texels/m (1.04 M texels) at 256 spp, REPS times (the first
# with the driver's shader cache cold), each call's wall time and its JSON `seconds` per stage, the
# ratio whole call / lighting (issue 33's goal: <= 1.3); then bench_host_stages on the same bundle
# (the host's part of load and write, no device), and the previous exitance-relight when packed.
# Prints the tables and copies them with the JSONs to $OUT.
#   bash .replay/host_stages_gpu_run.sh        (env: REPS, default 3; SPP, default 256)
set -e
for f in .gl/*.deb; do dpkg -x $f / ; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
W=/tmp/w; mkdir -p $W && tar -C $W -xJf .replay/host_stages.txz
export LD_LIBRARY_PATH=$W/runtime/lib
S=$W/summary.txt
{ nvidia-smi --query-gpu=name,driver_version --format=csv,noheader; echo "host: $(nproc) hardware threads"; } > $S
relight() {  # $1 binary, $2 label, $3 rep
  local start end
  start=$(date +%s.%N)
  $1 $W/building.bake -o $W/out_$2.bake --spp ${SPP:-256} --seed 1 --json > $W/$2_$3.json
  end=$(date +%s.%N)
  python3 - "$W/$2_$3.json" "$2" "$3" "$start" "$end" >> $S <<'PY'
import json, sys
r = json.load(open(sys.argv[1])); s = r['seconds']; wall = float(sys.argv[5]) - float(sys.argv[4])
order = ['load', 'edits', 'lighting', 'read_back', 'probes', 'exitance', 'write']
cells = ' | '.join('%.3f' % s[k] if k in s else '' for k in order)
print('| %s %s | %s | %.3f | %.2f | %d |' % (sys.argv[2], sys.argv[3], cells, wall, wall / s['lighting'], r['live_texels']))
PY
}
echo "| run | load | edits | lighting | read back | probes | exitance | write | whole call s | whole / lighting | live texels |" >> $S
echo "|---|---|---|---|---|---|---|---|---|---|---|" >> $S
for rep in $(seq 1 ${REPS:-3}); do
  relight $W/runtime/bin/exitance-relight after $rep
  if [ -x $W/before/exitance-relight ]; then relight $W/before/exitance-relight before $rep; fi
done
echo >> $S
echo "load split (seconds.load_split: RefreshSession::open's parts):" >> $S
for j in $W/after_*.json; do
  python3 -c "import json,sys; r=json.load(open(sys.argv[1])); print(sys.argv[1].split('/')[-1], {k: round(v, 3) for k, v in r['seconds'].get('load_split', {}).items()})" $j >> $S
done
echo >> $S
echo "bench_host_stages (host part of load and write, no device):" >> $S
$W/bench_host_stages $W/building.bake --out $W/hs.bake --repeat 3 >> $S
cat $S
if [ -n "$OUT" ]; then cp $S $W/*.json "$OUT"/; fi
