# another machine: Push's default command and a 5-seed HER Push sweep, base = d851150 vs the working tree
set -u
source call.sh  # runs PAIRS (Push) and defines run()
for code in new base; do
  run her5-$code $code 170 python -m splid_jax.sweep --env push --algo her --seed 2000 --seeds 5 --iterations 500 --compile-cache=
done
