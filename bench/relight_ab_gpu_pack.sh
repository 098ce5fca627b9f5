#!/bin/bash
# Here (the build machine): packs an A/B of two exitance-relight programs on one bundle into
# .replay/relight_ab.txz for bench/relight_ab_gpu_run.sh: this build's runtime folder ("after") and
# an earlier exitance-relight ("before", e.g. built from another commit), and the bundle's manifest,
# scene.bin, probes.bin and svo.bin.
#   bash bench/relight_ab_gpu_pack.sh BUILD_DIR BEFORE_RELIGHT BUNDLE
set -e
build=$1; before=$2; bundle=$3
[ -x "$before" ] && [ -f "$bundle/manifest.json" ] || { echo "usage: relight_ab_gpu_pack.sh BUILD_DIR BEFORE_RELIGHT BUNDLE"; exit 2; }
work=$(mktemp -d)
mkdir -p $work/pack/bundle.bake
for f in manifest.json scene.bin probes.bin svo.bin; do [ -f $bundle/$f ] && cp $bundle/$f $work/pack/bundle.bake/; done
cmake --install $build --component runtime --prefix $work/pack/rt > /dev/null
cp "$before" $work/pack/before
mkdir -p .replay
tar -C $work/pack -cf - . | xz -2 -T2 > .replay/relight_ab.txz
cp bench/relight_ab_gpu_run.sh .replay/
rm -rf $work
ls -la .replay/relight_ab.txz
