"""The presets resolve to their documented settings: the paper's Algorithm 2 (with the authors' code where the
paper is silent) and the tuned defaults, for SPLID and each baseline."""

import dataclasses

import jax
import optax
import pytest

import envs
from splid_jax import presets
from splid_jax.common.errors import InvalidConfig
from splid_jax.config import TrainConfig
from splid_jax.learners.her.config import BASELINES, HerConfig
from splid_jax.learners.imitation.config import RELABELS, STANDING_STILL
from splid_jax.learners.splid import relabel

# The paper preset as the paper (section 4.1, Algorithm 2) and the authors' code (decisionforce/ESPD) give it
PAPER = {
    "relabel": "paper",
    "select": True,
    "horizon": 8,
    "horizon_end": 0,
    "sigma": 1.0,
    "sigma_end": 1.0,
    "sigma_anneal": 1,
    "policy_ema": 0.0,
    "explore_subgoal_reach": 0.0,
    "eval_subgoal_reach": 0.0,
    "buffer_size": 100_000,
    "buffer_window": 0,
    "buffer_window_grow": 0,
    "hidden": (64, 64, 64),
    "normalise": False,
    "relative_goal": False,
    "optimiser": "rmsprop",
    "learning_rate": 3e-4,
    "batch_size": 25,
    "bc_reuse": 30.0,
    "bc_steps": 5_000,
    "num_envs": 50,
    "env_options": "",
}


def resolved(cfg: TrainConfig) -> dict:
    return {name: getattr(cfg, name) for name in PAPER}


@pytest.mark.parametrize("env", ["push", "slide", "pick_and_place", "point"])
def test_the_paper_preset_is_the_documented_table_on_every_task(env):
    cfg = TrainConfig(env=env, preset="paper")
    assert resolved(cfg) == PAPER
    assert cfg.iterations * cfg.num_envs == pytest.approx(TrainConfig(env=env).iterations * TrainConfig(
        env=env).num_envs, rel=0.03)  # fmt: skip  # the tuned preset's episode budget
    assert set(presets.PAPER_SOURCES) == set(PAPER)  # every value says where it came from
    assert all(source for _, source in presets.PAPER_SOURCES.values())


def test_the_paper_preset_of_each_baseline():
    gcsl = TrainConfig(env="push", algo="gcsl", preset="paper")
    pchid = TrainConfig(env="push", algo="pchid", preset="paper")
    for cfg in (gcsl, pchid):
        assert {k: v for k, v in resolved(cfg).items() if k not in ("relabel", "select", "horizon_end")} == {
            k: v for k, v in PAPER.items() if k not in ("relabel", "select", "horizon_end")
        }
    assert gcsl.gcsl_relabel == "final" and pchid.pchid_every == 200 // (2 * 8)  # H grows 1..8 over half the run
    ablation = TrainConfig(env="push", preset="paper", select=False)  # SPLID without SELECT
    assert resolved(ablation) == {**PAPER, "select": False}
    her = TrainConfig(env="pick_and_place", algo="her", preset="paper")  # Baselines: 2 episodes x 8 workers a cycle
    assert (her.num_envs, her.eval_every, her.iterations, her.env_options) == (16, 50, 3200, "")
    assert her.learner_config() == HerConfig(**BASELINES)
    mrl = TrainConfig(env="pick_and_place", algo="her")  # the tuned HER: mrl's
    assert (mrl.num_envs, mrl.eval_every, mrl.iterations, mrl.learner_config()) == (8, 25, 2500, HerConfig())
    given = TrainConfig(env="push", algo="her", preset="paper", her_options="hidden=512,512,512")
    assert given.learner_config() == HerConfig(**{**BASELINES, "hidden": (512, 512, 512)})
    assert TrainConfig.from_json(given.to_json()) == given  # its recorded options read the same again
    es = TrainConfig(env="push", algo="es", preset="paper")
    assert es.learner_config() == TrainConfig(env="push", algo="es").learner_config()  # Salimans et al.'s


def test_the_tuned_preset_is_the_default_and_a_given_value_replaces_a_presets():
    assert TrainConfig(env="push") == TrainConfig(env="push", preset="tuned")
    push = TrainConfig(env="push")
    assert (push.relabel, push.horizon, push.horizon_end, push.sigma_end, push.policy_ema) == ("stop", 12, 8, 0.2, 0.98)
    assert TrainConfig(env="push", preset="paper", horizon=5).horizon == 5
    with pytest.raises(InvalidConfig, match="invalid preset='nope': must be one of tuned, paper"):
        TrainConfig(env="push", preset="nope")


def test_the_paper_preset_clones_with_rmsprop():
    from splid_jax.learners.splid.trainer import Trainer, optimiser

    cfg = TrainConfig(env="point", preset="paper", bc_steps=10)
    state = Trainer(envs.make("point"), cfg).init(jax.random.PRNGKey(0))
    kinds = {type(s).__name__ for s in jax.tree.leaves(state.opt_state, is_leaf=lambda x: hasattr(x, "_fields"))}
    assert "ScaleByRmsState" in kinds and "ScaleByAdamState" not in kinds
    # PyTorch's RMSprop: v = 0.99 v + 0.01 g^2, step lr g / (sqrt(v) + eps)
    update, _ = optimiser("rmsprop", 0.1).update({"w": jax.numpy.float32(2.0)}, optimiser("rmsprop", 0.1).init(
        {"w": jax.numpy.float32(0.0)}))  # fmt: skip
    assert float(update["w"]) == pytest.approx(-0.1 * 2.0 / (0.1 * 2.0 + 1e-8), rel=1e-5)
    assert isinstance(optimiser("adam", 0.1), optax.GradientTransformation)


def test_the_relabellings_named_in_the_config_are_selects_strategies():
    assert RELABELS == relabel.NAMES and relabel.HOLDING == ("hold", "stop", "exact")
    assert STANDING_STILL == tuple(name for name, s in relabel.STRATEGIES.items() if s.stands_still)
    fields = {f.name for f in TrainConfig.settings_fields()}
    assert not fields & {"hold_horizon", "rest_horizon", "select_radius"}  # retired


def test_the_run_config_holds_the_runs_settings_and_each_learners_own_apart():
    own = [f.name for f in dataclasses.fields(TrainConfig)]
    assert len(own) <= 20 and "cloning" in own and not set(own) & {"horizon", "sigma", "learning_rate"}
    cfg = TrainConfig(env="push", horizon=8)
    assert cfg.cloning == cfg.learner_config() and cfg.horizon == cfg.cloning.horizon == 8
    assert dataclasses.replace(cfg, horizon=5).cloning.horizon == 5
    assert set(cfg.to_json()) == {f.name for f in TrainConfig.settings_fields()}  # config.json: flat, as ever
