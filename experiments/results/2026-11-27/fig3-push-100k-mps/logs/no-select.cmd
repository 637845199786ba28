python -m splid_jax.figures fig3 --env push --episodes 100000 --methods no-select --set checkpoint_every=0 --out /tmp/fig/no-select --compile-cache= --quiet
