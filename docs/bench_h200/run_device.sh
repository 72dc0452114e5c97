#!/bin/bash
# Real-GPU measurements for cumulus (one shot). Results tarred into $OUT/res.tgz after each step.
R=/tmp/res; mkdir -p $R
pack() { tar czf $OUT/res.tgz -C $R . ; }
log() { echo "== $(date +%T) $*" | tee -a $R/steps.txt; }
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
ls /usr/share/vulkan/icd.d /etc/vulkan/icd.d /usr/local/nvidia/share/vulkan/icd.d > $R/icd.txt 2>&1
if ! ls /usr/share/vulkan/icd.d/*nvidia* /etc/vulkan/icd.d/*nvidia* >/dev/null 2>&1; then
  export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json __EGL_VENDOR_LIBRARY_FILENAMES=/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json
fi
{ nvidia-smi -L; nvidia-smi --query-gpu=name,driver_version,clocks.max.sm --format=csv; nproc; lscpu | grep 'Model name'; } > $R/gpu.txt 2>&1
mkdir -p target/release
for f in .dev/*.gz; do n=$(basename $f .gz); gunzip -c $f > target/release/$n; chmod +x target/release/$n; done
[ -e /work/main ] || { mkdir -p /work; ln -s "$PWD" /work/main; }
C=target/release/cumulus
sed 's/surface = "sea"/surface = "land"/' scenes/bomex.toml > scenes/zz_bomex_land.toml
{ cat scenes/fair_weather.toml; printf '\n[render.atmosphere]\nmodel = "analytic"\n'; } > scenes/zz_fw_analytic.toml
export CUMULUS_REQUIRE_GPU=1
log smoke
timeout 60 $C render --scene scenes/fair_weather.toml --backend gpu --width 320 --height 240 --frames 1 --time-frames 3 --out $R/smoke.png > $R/smoke.txt 2>&1 || { log SMOKE FAILED; cat $R/smoke.txt; pack; exit 1; }
cat $R/smoke.txt | tail -6; pack
for s in fair_weather zz_fw_analytic bomex zz_bomex_land evening endless automaton spheroids deep_convection view_backlit view_horizon view_high_flight view_below_base; do
  for wh in "640 480" "1920 1080"; do set -- $wh
    [ $SECONDS -gt 200 ] && { log skip $s $1; continue; }
    log render $s $1x$2
    timeout 45 $C render --scene scenes/$s.toml --backend gpu --width $1 --height $2 --frames 1 --time-frames 30 --out $R/${s}_$1.png > $R/render_${s}_$1.txt 2>&1
  done
done
for f in $R/*_1920.png; do case $f in *fair_weather_1920.png) ;; *) rm -f $f;; esac; done; pack
log bench
bt=$((430-SECONDS)); [ $bt -gt 240 ] && bt=240
timeout $bt $C bench --out $R/bench --max-frame-s 1 > $R/bench.txt 2>&1; log bench rc $?; pack
log tests
tt=$((545-SECONDS)); [ $tt -gt 120 ] && tt=120
cd target/release
for t in render_gpu embedding sky_luts_gpu light_volume_gpu bench_gpu; do
  (cd /work/main && timeout $tt target/release/$t --test-threads 4 > $R/test_$t.txt 2>&1; echo "rc $?" >> $R/test_$t.txt) &
done
wait; cd /work/main
log done; grep -h "test result\|^rc\|FAILED\|panicked" $R/test_*.txt; pack
