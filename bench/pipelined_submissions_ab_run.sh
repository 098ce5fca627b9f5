# On the GPU machine (carry .gl and .replay; .replay/ab.txz: rt-main and rt-pipe runtime folders from
# `cmake --install BUILD --component runtime` of main and of branch pipelined-submissions-wip, and the
# building and city bundles of bench/open_city_gpu_pack.sh / the building command in open-city-gpu.md).
set -e
for f in .gl/*.deb; do dpkg -x $f / ; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
mkdir -p /tmp/w && tar -C /tmp/w -xJf .replay/ab.txz
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
for b in building city; do
  /tmp/w/rt-main/bin/exitance-relight /tmp/w/$b.bake -o /tmp/w/warm.bake --spp 16 --seed 1 --json > /dev/null
  for rep in 1 2 3; do
    for v in main pipe; do
      timeout 120 /tmp/w/rt-$v/bin/exitance-relight /tmp/w/$b.bake -o /tmp/w/out-$v-$b.bake --spp 256 --seed 1 --json > /tmp/w/r.json
      printf "%s %s rep %s: " $b $v $rep; grep -E '"(lighting_seconds|rays_per_second)"' /tmp/w/r.json | tr -d '\n '; echo
    done
  done
  md5sum /tmp/w/out-main-$b.bake/lightmap-*.exr /tmp/w/out-pipe-$b.bake/lightmap-*.exr | sed 's|/tmp/w/||'
done
