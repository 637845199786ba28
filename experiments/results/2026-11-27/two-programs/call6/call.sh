# a fresh machine: Push's default command new/base/new, PickAndPlace's new/base (base = d851150, one program per chunk)
set -u
PAIRS="new-1 base-1 new-2" source ../call.sh
for pair in new-p base-p; do code=${pair%-*}
  run pnp-$pair $code 150 python -m splid_jax.train --env pick_and_place --compile-cache=
done
