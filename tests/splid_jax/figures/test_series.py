"""A figure's legend names whose HER each curve ran: mrl's (the default) or OpenAI Baselines' (the paper's)."""

import dataclasses

import pytest

from splid_jax.config import TrainConfig
from splid_jax.figures.planning import plan
from splid_jax.figures.registry import SPECS
from splid_jax.figures.series import her_settings
from splid_jax.learners.her.config import BASELINES, HerConfig, settings_name


def test_her_settings_are_named_mrl_or_baselines_whatever_the_products_precision():
    assert settings_name(HerConfig()) == "mrl"
    assert settings_name(HerConfig(compute_dtype="bfloat16", matmul_precision="float32")) == "mrl"
    assert settings_name(HerConfig(**BASELINES)) == "Baselines"
    assert settings_name(HerConfig(batch_size=256)) is None  # settings of one's own are not named as another's


@pytest.mark.parametrize(("method", "name", "num_envs"), [("her", "mrl", 8), ("her-baselines", "Baselines", 16)])
def test_fig3_trains_her_at_mrls_settings_and_her_baselines_at_the_papers(tmp_path, method, name, num_envs):
    (p,) = plan(SPECS["fig3"], "push", (method,), 1, 20_000, {None: {}}, str(tmp_path))
    assert settings_name(p.base.learner_config()) == name and p.base.num_envs == num_envs
    assert p.base.iterations * p.episodes_per_iteration == 20_000


def test_a_her_runs_record_names_its_settings_also_for_runs_recorded_before_the_presets():
    tuned = TrainConfig(env="push", algo="her", preset="tuned").to_json()
    paper = TrainConfig(env="push", algo="her", preset="paper").to_json()
    assert her_settings(tuned) == "mrl" and her_settings(paper) == "Baselines"
    # a run written while Baselines' settings were HER's defaults records neither preset nor her_defaults
    old = {k: v for k, v in tuned.items() if k not in ("preset", "her_defaults")}
    assert her_settings({**old, "her_options": ""}) == "Baselines"
    own = dataclasses.replace(TrainConfig(env="push", algo="her"), her_options="batch_size=64").to_json()
    assert her_settings(own) is None
