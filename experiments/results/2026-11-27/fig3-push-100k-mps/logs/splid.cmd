python -m splid_jax.figures fig3 --env push --episodes 100000 --methods splid --set checkpoint_every=100 --out /tmp/fig/splid --compile-cache= --quiet
