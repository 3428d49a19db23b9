#!/bin/bash
# GI accuracy of one transgi binary on the scenes docs/results.md tracks (issue 16,
# "Where the deficit was"): mean GI / reference, RMSE and SSIM per scene and preset.
#
#   scripts/gi_accuracy.sh [TRANSGI_BINARY] [OUT_DIR]      (extra render options in $X)
#
# Needs ../shared/scenes (Bitterli's Living Room and Breakfast Room), the models
# out/bitterli/bitterli.tgm and out/breakfast/breakfast.tgm, the ground-plane variants and
# their reference (docs/results.md, issue 16), the Breakfast Room's eval reference
# out/bf16/decomp/images/reference_gi.exr, out/mv_ref4096.exr (docs/performance.md) and
# out/level_ref1024.exr (render --method reference --pass gi --spp 1024 of the sample level).
# About 5 minutes on 2 cores.
set -euo pipefail
T=${1:-./build/release/modules/transgi/transgi}
o=${2:-out/gi_accuracy}
C=./build/release/modules/transgi/transgi  # compares with this tree's binary
B=../shared/scenes/bitterli-breakfast-room/scene.gltf
LR=../shared/scenes/bitterli-living-room
G=out/breakfast_ground/scene.gltf
GV=out/breakfast_ground_vol/scene.gltf
L=content/levels/living_room/scene.gltf
M=content/levels/living_room/transgi.tgm
X=${X:-}
mkdir -p "$o"
row() {
  printf "%-30s " "$1"
  "$C" compare "$2" "$3" | tail -1 | python3 -c \
    "import json,sys; j=json.load(sys.stdin); print('mean %.3f rmse %.4f ssim %.3f' % (1/j['mean_ratio'], j['rmse'], j['ssim']))"
}
render() { "$T" render --method transgi --pass gi --width 320 --height 180 "$@" $X > /dev/null 2>&1; }
quality=(--preset quality --frames 160)
realtime=(--preset realtime --frames 128)
render --scene $B --model out/breakfast/breakfast.tgm "${quality[@]}" --out $o/bq.exr
row "breakfast quality" out/bf16/decomp/images/reference_gi.exr $o/bq.exr
render --scene $B --model out/breakfast/breakfast.tgm "${realtime[@]}" --out $o/brt.exr
row "breakfast realtime" out/bf16/decomp/images/reference_gi.exr $o/brt.exr
render --scene $LR/scene.gltf --model out/bitterli/bitterli.tgm "${quality[@]}" --out $o/lq.exr
row "living quality (cycles)" $LR/cycles-reference/cycles-320x180_gi.exr $o/lq.exr
render --scene $LR/scene.gltf --model out/bitterli/bitterli.tgm "${realtime[@]}" --out $o/lrt.exr
row "living realtime (cycles)" $LR/cycles-reference/cycles-320x180_gi.exr $o/lrt.exr
for p in quality realtime; do
  if [ $p = quality ]; then preset=("${quality[@]}"); else preset=("${realtime[@]}"); fi
  render --scene $G --model out/breakfast/breakfast.tgm --allow-unbaked "${preset[@]}" --out $o/g_$p.exr
  row "ground cascades $p" out/breakfast_ground/ref_gi_4096.exr $o/g_$p.exr
  render --scene $GV --model out/breakfast/breakfast.tgm --allow-unbaked "${preset[@]}" --probe-volume authored --out $o/gv_$p.exr
  row "ground authored $p" out/breakfast_ground/ref_gi_4096.exr $o/gv_$p.exr
done
render --scene $L --model $M "${quality[@]}" --out $o/lvq.exr
row "level quality (1024 spp)" out/level_ref1024.exr $o/lvq.exr
"$T" bench-frame --scene $L --model $M --width 320 --height 180 --frames 128 --warmup 32 --gi-out $o/mv.exr > /dev/null 2>&1
row "level moving realtime" out/mv_ref4096.exr $o/mv.exr
