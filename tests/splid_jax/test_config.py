import dataclasses

import pytest

from envs.base import InvalidConfig
from splid_jax.config import TrainConfig, saved_fields


def test_a_run_saved_before_policy_ema_existed_keeps_acting_with_the_cloned_parameters():
    new = TrainConfig(env="push")
    assert new.policy_ema > 0  # today's Push default averages
    old = {k: v for k, v in new.to_json().items() if k != "policy_ema"}
    old["retired_field"] = 1  # keys a later version no longer knows are dropped
    assert TrainConfig(**saved_fields(old)).policy_ema == 0.0
    assert TrainConfig(**saved_fields(new.to_json())) == new  # a current config.json round-trips


@pytest.mark.parametrize("value", [-0.1, 1.0, 1.5])
def test_policy_ema_outside_its_range_names_the_field(value):
    with pytest.raises(InvalidConfig, match="policy_ema"):
        TrainConfig(env="point", policy_ema=value)


def test_every_field_has_help():
    for f in dataclasses.fields(TrainConfig):
        assert f.metadata.get("help"), f.name
