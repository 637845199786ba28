"""The registry is the one table of learners: each name builds its own learner from its own settings,
and what a learner does not read is refused, whatever the name."""

import dataclasses

import jax
import pytest

import envs
from splid_jax.common.errors import InvalidConfig
from splid_jax.config import TrainConfig
from splid_jax.learners import registry
from splid_jax.learners.es.config import EsConfig
from splid_jax.learners.es.learner import ES
from splid_jax.learners.her.config import HerConfig
from splid_jax.learners.her.learner import HER
from splid_jax.learners.imitation.config import ImitationConfig
from splid_jax.learners.splid.trainer import Trainer

EXPECTED = {"splid": (ImitationConfig, Trainer), "gcsl": (ImitationConfig, Trainer),
            "pchid": (ImitationConfig, Trainer), "her": (HerConfig, HER), "es": (EsConfig, ES)}  # fmt: skip


def test_every_name_builds_its_own_learner_from_its_own_settings():
    assert registry.names() == list(EXPECTED)
    env = envs.make("point")
    for name, (settings, learner) in EXPECTED.items():
        cfg = TrainConfig(env="point", algo=name, hidden=(8,) if name != "her" else None)
        assert type(cfg.learner_config()) is settings
        algo = registry.make_algorithm(cfg, env)
        assert type(algo) is learner and algo.name == name
        # what a sweep's members may hold apart: each such setting changes the learner's traced values
        hyper = algo.hyper()
        assert (hyper == {}) == (registry.get(name).sweeps == ()), name
        for field in registry.get(name).sweeps:
            value = getattr(cfg, field)
            changed = {field: value + 1 if isinstance(value, int) else value / 2 + 0.1}
            base = dataclasses.replace(cfg, buffer_window=1) if field == "buffer_window_grow" else cfg  # grows from it
            base = dataclasses.replace(base, relabel="stop") if field == "held_share" else base  # stop's held pairs
            other = dataclasses.replace(base, **changed)
            same = jax.tree.map(lambda a, b: a == b, algo.hyper(other), algo.hyper(base))
            assert not all(jax.tree.leaves(same)), field


def test_a_learner_reads_its_settings_and_the_runs_and_ignores_the_others():
    learners_own = {*registry.IMITATION_FIELDS, "her_options", "es_options"}
    run_fields = [f.name for f in TrainConfig.settings_fields() if f.name not in learners_own]
    for name in registry.names():
        assert all(registry.reads(name, f) for f in run_fields if f != "num_envs"), name
    assert registry.ignores("splid") == ("gcsl_relabel", "pchid_every")
    assert set(registry.ignores("gcsl")) == {*registry.SELECT_FIELDS, "pchid_every"}
    assert registry.ignores("pchid") == ("horizon_end", "gcsl_relabel")  # its horizon grows instead
    assert set(registry.ignores("her")) == set(registry.IMITATION_FIELDS)
    assert set(registry.ignores("es")) == set(registry.IMITATION_FIELDS) - {"hidden"}
    assert not registry.reads("es", "num_envs") and registry.reads("her", "num_envs")


def test_only_the_cloning_learners_split_a_run_and_sweep_their_settings():
    splits = {name for name, x in registry.LEARNERS.items() if x.splits_envs}
    assert splits == {"splid", "gcsl", "pchid"}
    traced = ("sigma", "horizon", "horizon_end", "sigma_end", "learning_rate", "policy_ema", "gripper_hold")
    traced += ("explore_subgoal_reach", "bc_reuse", "held_share", "buffer_window", "buffer_window_grow")
    assert all(registry.get(n).sweeps == (traced if n in splits else ()) for n in registry.names())
    assert [n for n, x in registry.LEARNERS.items() if x.grows_horizon] == ["pchid"]
    assert [n for n, x in registry.LEARNERS.items() if x.clones_every_pair] == ["gcsl"]


def test_an_unknown_name_fails_naming_the_field():
    with pytest.raises(InvalidConfig, match="invalid algo='ppo': must be one of splid, gcsl, pchid, her, es"):
        registry.get("ppo")


@pytest.mark.parametrize("field, value", [("policy_ema", 1.0), ("relabel", "nearest"), ("bc_steps", -1)])
def test_the_cloning_settings_are_checked_on_construction(field, value):
    good = TrainConfig(env="point").learner_config()
    with pytest.raises(InvalidConfig, match=f"invalid {field}="):
        dataclasses.replace(good, **{field: value})
