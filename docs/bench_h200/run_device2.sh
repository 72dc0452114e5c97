#!/bin/bash
# Second H200 run: per-table sky LUT timings, twin-parity figures on NVIDIA, and the CPU side of a P upload after the parallel spread.
R=/tmp/res; mkdir -p $R
pack() { tar czf $OUT/res2.tgz -C $R . ; }
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
{ pwd -P; ls -la /work 2>&1; readlink -f /work/main; } > $R/paths.txt
mkdir -p target/release
for f in .dev/*.gz; do n=$(basename $f .gz); gunzip -c $f > target/release/$n; chmod +x target/release/$n; done
[ -e /work/main ] || { mkdir -p /work; ln -s "$PWD" /work/main; }
export CUMULUS_REQUIRE_GPU=1
cd /work/main || cd -
for t in sky_luts_gpu light_volume_gpu render_gpu embedding bench_gpu; do
  echo "== $t $(date +%T)"
  timeout 120 target/release/$t --test-threads 1 --nocapture > $R/test_$t.txt 2>&1; echo "rc $?" >> $R/test_$t.txt
  grep -h "test result\|^rc" $R/test_$t.txt; pack
done
echo "== bench quick $(date +%T)"
timeout 120 target/release/cumulus bench --quick --out $R/bq > $R/bench_quick.txt 2>&1; echo "rc $?" >> $R/bench_quick.txt
grep -A5 "physics + projection" $R/bench_quick.txt; pack
