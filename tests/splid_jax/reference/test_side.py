"""The reference side's run loading: a pads policy loads on a MuJoCo its contact was not checked on."""

import envs.physics
from splid_jax.config import TrainConfig
from splid_jax.reference import side


def test_pads_load_with_the_box_fingers_inputs_only_off_the_kernels_release(monkeypatch):
    cfg = TrainConfig(env="slide", env_options="finger=pads,finger_table=1,drive=weld")
    monkeypatch.setattr(envs.physics, "kernels_checked", lambda: True)
    assert side.loadable(cfg) is cfg  # the release the pads were checked on builds them
    monkeypatch.setattr(envs.physics, "kernels_checked", lambda: False)
    other = side.loadable(cfg)
    assert other.env_options == "finger=box,finger_table=1,drive=weld,hand_pitch=0.0" and other.env == "slide"
    default = side.loadable(TrainConfig(env="slide"))  # Slide's default fingers are the pads
    assert default.env_options == "finger=box,hand_pitch=0.0"
    plain = TrainConfig(env="push", env_options="drive=weld")
    assert side.loadable(plain) is plain
