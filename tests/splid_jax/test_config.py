import dataclasses
import json

import pytest

import envs
from splid_jax.common.errors import InvalidConfig
from splid_jax.config import TrainConfig


def test_a_saved_config_round_trips():
    cfg = TrainConfig(env="push")
    assert TrainConfig(**json.loads(json.dumps(cfg.to_json()))) == cfg


@pytest.mark.parametrize("value", [-0.1, 1.0, 1.5])
def test_policy_ema_outside_its_range_names_the_field(value):
    with pytest.raises(InvalidConfig, match="policy_ema"):
        TrainConfig(env="point", policy_ema=value)


@pytest.mark.parametrize("seed", [-1, 2**32, 99999999999999999999])
def test_seed_outside_the_prng_range_names_the_field(seed):
    with pytest.raises(InvalidConfig, match="seed"):
        TrainConfig(env="point", seed=seed)


@pytest.mark.parametrize("field", [f.name for f in TrainConfig.settings_fields() if f.type == "float"])
@pytest.mark.parametrize("value", [float("inf"), float("-inf"), float("nan")])
def test_every_float_field_must_be_finite(field, value):
    with pytest.raises(InvalidConfig, match=f"invalid {field}=.*finite"):
        TrainConfig(env="point", **{field: value})


def test_every_field_has_help():
    for f in TrainConfig.settings_fields():
        assert f.metadata.get("help"), f.name


def test_pchid_schedule_is_resolved_once_so_a_longer_resume_keeps_it():
    cfg = TrainConfig(env="point", algo="pchid", iterations=40, horizon=4, eval_every=5)
    assert cfg.pchid_every == 5  # H reached half-way: 40 // (2 * 4)
    resumed = TrainConfig(**{**cfg.to_json(), "hidden": tuple(cfg.hidden), "iterations": 80})
    assert resumed.pchid_every == 5
    assert TrainConfig(env="point", iterations=40).pchid_every == 0  # other learners leave it unset


@pytest.mark.parametrize("field, value", [("sigma_end", -0.1), ("sigma_end", 1.5), ("sigma_anneal", 0)])
def test_sigma_schedule_outside_its_range_names_the_field(field, value):
    with pytest.raises(InvalidConfig, match=field):
        TrainConfig(env="point", **{field: value})


@pytest.mark.parametrize(
    "fields",
    [
        {"horizon_end": -1},
        {"horizon_end": 9},  # above the horizon 8
    ],
)
def test_select_horizons_outside_their_range_name_the_field(fields):
    name = next(k for k in fields if "horizon" in k)
    with pytest.raises(InvalidConfig, match=name):
        TrainConfig(env="point", **fields)


@pytest.mark.parametrize("lanes", [0.0, 8.5])  # above the horizon 8: more lanes than candidates
def test_select_lanes_outside_zero_to_the_horizon_names_the_field(lanes):
    with pytest.raises(InvalidConfig, match="select_lanes"):
        TrainConfig(env="point", select_lanes=lanes)
    assert TrainConfig(env="point", select_lanes=8).select_lanes == 8


@pytest.mark.parametrize(
    "fields",
    [
        {"buffer_window": -1},
        {"buffer_window": 20_001, "buffer_size": 20_000},
        {"bc_reuse": -1.0},
        {"buffer_window_grow": -1, "buffer_window": 5_000},
        {"buffer_window_grow": 100},  # without a window: the whole buffer already
        {"held_share": 1.0, "relabel": "stop"},
        {"held_share": 0.2, "relabel": "hold"},  # only stop's held pairs carry the zero action
    ],
)
def test_a_buffer_window_beyond_the_buffer_or_a_negative_reuse_names_the_field(fields):
    with pytest.raises(InvalidConfig, match=f"invalid {next(iter(fields))}="):
        TrainConfig(env="point", **fields)
    assert TrainConfig(env="point", buffer_size=20_000, buffer_window=5_000, bc_reuse=30.0).buffer_window == 5_000
    assert TrainConfig(env="point", buffer_size=20_000, buffer_window=5_000, buffer_window_grow=40).buffer_window_grow
    assert TrainConfig(env="push", held_share=0.2).held_share == 0.2  # Push's default relabelling is stop


def test_gripper_hold_is_checked_against_the_task():
    import envs

    with pytest.raises(InvalidConfig, match="gripper_hold"):
        TrainConfig(env="pick_and_place", gripper_hold=0)
    for name in ("push", "point"):  # fingers locked, or none: their noise cannot be held
        with pytest.raises(InvalidConfig, match="invalid gripper_hold=5: must be 1 on this task"):
            TrainConfig(env=name, gripper_hold=5).check_env(envs.make(name))
    carry = envs.make("pick_and_place")
    TrainConfig(env="pick_and_place", gripper_hold=carry.episode_length).check_env(carry)
    with pytest.raises(InvalidConfig, match="gripper_hold"):
        TrainConfig(env="pick_and_place", gripper_hold=carry.episode_length + 1).check_env(carry)


def test_a_checkpoint_records_a_later_setting_only_when_it_is_set():
    from splid_jax.runtime.run_files import identity

    later = ("gripper_hold", "horizon_end", "preset", "optimiser")
    assert not set(later) & set(identity(TrainConfig(env="pick_and_place")))  # as runs recorded before them
    changed = identity(TrainConfig(env="pick_and_place", gripper_hold=5, horizon_end=6, preset="paper"))
    assert (changed["gripper_hold"], changed["horizon_end"], changed["preset"], changed["optimiser"]) == (
        5, 6, "paper", "rmsprop"
    )


def test_push_horizon_falls_from_12_to_8_unless_the_caller_sets_h():
    from splid_jax.runtime.run_files import identity

    horizons = lambda **kw: (lambda c: (c.horizon, c.horizon_end))(TrainConfig(env="push", **kw))  # noqa: E731
    assert horizons() == (12, 8) and TrainConfig(env="push").sigma_end == 0.2
    assert horizons(horizon=8) == horizons(horizon=8, horizon_end=0) == (8, 0)  # a given H is kept throughout
    assert horizons(horizon=16, horizon_end=4) == (16, 4)
    assert horizons(horizon_end=10) == (12, 10)
    assert horizons(algo="pchid") == (8, 0)  # PCHID grows its own horizon to the paper's H
    assert (lambda c: (c.horizon, c.horizon_end))(TrainConfig(env="slide")) == (8, 0)
    # a Push run recorded before the falling horizon (H = 8, no horizon_end) resumes as it ran
    before = {k: v for k, v in TrainConfig(env="push").to_json().items() if k != "horizon_end"}
    resumed = TrainConfig.from_json({**before, "horizon": 8})
    assert (resumed.horizon, resumed.horizon_end) == (8, 0)
    assert "horizon_end" not in identity(resumed)
    assert identity(TrainConfig(env="push"))["horizon_end"] == 8


def test_pick_and_place_trains_from_grasped_starts_unless_told_otherwise():
    assert TrainConfig(env="pick_and_place").env_overrides() == {"grasped_starts": 0.5}
    assert TrainConfig(env="pick_and_place", algo="her").env_overrides() == {"grasped_starts": 0}  # mrl's
    given = TrainConfig(env="pick_and_place", env_options="finger_drive=fast")  # the task's option stays
    assert given.env_overrides() == {"grasped_starts": 0.5, "finger_drive": "fast"}
    assert TrainConfig(env="pick_and_place", env_options="grasped_starts=0").env_overrides() == {"grasped_starts": 0}
    assert TrainConfig.from_json(given.to_json()) == given  # resolved once: a saved run reads back the same
    before = {**TrainConfig(env="pick_and_place").to_json(), "env_options": ""}  # saved before the default
    assert TrainConfig.from_json(before).env_overrides() == {}  # resumes from the standard starts it trained on
    spaced = {**before, "env_options": "grasped_starts=0, finger_drive=fast"}  # as a user wrote it then
    assert TrainConfig.from_json(spaced).env_options == spaced["env_options"]  # as its checkpoint recorded it
    assert TrainConfig(env="push").env_options == ""


def test_a_configs_task_carries_its_options():
    env = TrainConfig(env="point", env_options="max_episode_steps=20,door_half_width=0.5").make_env()
    assert (env.max_episode_steps, env.door_half_width) == (20, 0.5)
    assert TrainConfig(env="point").make_env() == envs.make("point")


def test_the_fetch_tasks_but_reach_evaluate_with_subgoals_and_runs_recorded_before_them_read_back_without():
    from splid_jax.runtime.run_files import identity

    assert TrainConfig(env="push").eval_subgoal_reach == 0.1
    assert TrainConfig(env="push", algo="her").eval_subgoal_reach == 0.1  # one controller for every learner
    assert TrainConfig(env="pick_and_place").eval_subgoal_reach == 0.1
    assert TrainConfig(env="slide").eval_subgoal_reach == 0.1
    assert TrainConfig(env="reach").eval_subgoal_reach == TrainConfig(env="point").eval_subgoal_reach == 0.0
    before = {k: v for k, v in TrainConfig(env="push").to_json().items() if k != "eval_subgoal_reach"}
    assert TrainConfig.from_json(before).eval_subgoal_reach == 0.0  # evaluated as it was
    assert "eval_subgoal_reach" not in identity(TrainConfig.from_json(before))  # and resumes from its checkpoint
    assert identity(TrainConfig(env="push"))["eval_subgoal_reach"] == 0.1
    with pytest.raises(InvalidConfig, match="eval_subgoal_reach"):
        TrainConfig(env="push", eval_subgoal_reach=-0.1)


def test_splid_explores_steered_on_push_slide_and_pick_and_place_and_the_baselines_towards_the_goal():
    from splid_jax.runtime.run_files import identity

    assert TrainConfig(env="push").explore_subgoal_reach == 0.1
    assert TrainConfig(env="pick_and_place", algo="splid", select=False).explore_subgoal_reach == 0.1
    assert TrainConfig(env="pick_and_place", algo="gcsl").explore_subgoal_reach == 0.0  # baselines as published
    assert TrainConfig(env="push", algo="pchid").explore_subgoal_reach == 0.0
    assert TrainConfig(env="push", algo="pchid", explore_subgoal_reach=0.1).explore_subgoal_reach == 0.1
    assert TrainConfig(env="slide").explore_subgoal_reach == 0.1
    assert TrainConfig(env="slide", algo="gcsl").explore_subgoal_reach == 0.0
    assert TrainConfig(env="reach").explore_subgoal_reach == TrainConfig(env="point").explore_subgoal_reach == 0.0
    assert TrainConfig(env="push", algo="her").explore_subgoal_reach == 0.0  # HER explores with its own noise
    assert TrainConfig(env="pick_and_place", algo="es").explore_subgoal_reach == 0.0
    before = {k: v for k, v in TrainConfig(env="push").to_json().items() if k != "explore_subgoal_reach"}
    assert TrainConfig.from_json(before).explore_subgoal_reach == 0.0  # older runs explored towards the goal
    assert "explore_subgoal_reach" not in identity(TrainConfig.from_json(before))  # and resume as they ran
    assert identity(TrainConfig(env="push"))["explore_subgoal_reach"] == 0.1
    assert TrainConfig(env="push", explore_subgoal_reach=0.0).explore_subgoal_reach == 0.0  # the goal itself
    with pytest.raises(InvalidConfig, match="explore_subgoal_reach"):
        TrainConfig(env="push", explore_subgoal_reach=-0.1)
    from splid_jax.learners import registry

    assert [registry.reads(a, "explore_subgoal_reach") for a in registry.names()] == [True, True, True, False, False]


def test_splid_on_push_clones_a_window_widening_to_200k_pairs_and_the_baselines_the_newest_50k():
    from splid_jax.runtime.run_files import identity

    buffer = lambda **kw: (lambda c: (c.buffer_size, c.buffer_window, c.buffer_window_grow))(  # noqa: E731
        TrainConfig(env="push", **kw)
    )
    assert buffer() == buffer(select=False) == (200_000, 50_000, 200)
    assert buffer(algo="gcsl") == buffer(algo="pchid") == (50_000, 0, 0)
    assert buffer(algo="her")[1:] == buffer(algo="es")[1:] == (0, 0)  # they read no window
    assert buffer(buffer_size=200_000) == (200_000, 0, 0)  # a given buffer is cloned whole unless told otherwise
    assert buffer(buffer_size=20_000) == (20_000, 0, 0)  # and never refused for a window the caller did not set
    assert buffer(buffer_window=30_000) == (200_000, 30_000, 0)
    assert buffer(buffer_window_grow=100) == (200_000, 50_000, 100)
    assert (lambda c: (c.buffer_window, c.buffer_window_grow))(TrainConfig(env="slide")) == (0, 0)
    # a Push run recorded before the window (the newest 50k pairs, no window fields) resumes as it ran
    before = {k: v for k, v in TrainConfig(env="push").to_json().items() if not k.startswith("buffer_window")}
    resumed = TrainConfig.from_json({**before, "buffer_size": 50_000})
    assert (resumed.buffer_size, resumed.buffer_window, resumed.buffer_window_grow) == (50_000, 0, 0)
    assert not {"buffer_window", "buffer_window_grow"} & set(identity(resumed))
    assert identity(TrainConfig(env="push"))["buffer_window_grow"] == 200


# config.json as the version before presets wrote it (flat, with the options since retired at their neutral values)
OLD_CONFIG = {
    "env": "point", "seed": 0, "iterations": 5, "num_envs": 8, "sigma": 1.0, "sigma_end": 1.0, "sigma_anneal": 1,
    "horizon": 8, "horizon_end": 0, "gripper_hold": 1, "explore_subgoal_reach": 0.0, "hold_horizon": 0,
    "rest_horizon": 0, "algo": "splid", "select": True, "relabel": "paper", "select_radius": 1.0,
    "gcsl_relabel": "final", "pchid_every": 0, "select_lanes": 1.0, "held_share": 0.0, "buffer_size": 200000,
    "buffer_window": 0, "buffer_window_grow": 0, "batch_size": 256, "bc_steps": 10, "bc_reuse": 0.0,
    "learning_rate": 0.001, "policy_ema": 0.0, "hidden": [64, 64, 64], "normalise": True, "relative_goal": False,
    "eval_every": 5, "eval_episodes": 8, "eval_subgoal_reach": 0.0, "checkpoint_every": 1, "num_devices": 1,
    "run_dir": "runs/old", "env_options": "", "her_options": "", "es_options": "", "devices": ["cpu:0"],
}  # fmt: skip


def test_an_old_config_json_loads_and_resumes_as_it_ran(tmp_path):
    from splid_jax.runtime.run_files import identity
    from splid_jax.train import build_parser, config_from_cli

    cfg = TrainConfig.from_json(OLD_CONFIG)
    now = TrainConfig(env="point", iterations=5, num_envs=8, eval_episodes=8, bc_steps=10, run_dir="runs/old")
    assert cfg == now and (cfg.preset, cfg.optimiser) == ("tuned", "adam")
    record = identity(cfg)  # what its checkpoint must hold: nothing the old version did not record as such
    assert record and all(k in OLD_CONFIG and OLD_CONFIG[k] == v for k, v in record.items())
    her = TrainConfig.from_json({**OLD_CONFIG, "algo": "her", "her_options": "batch_size=64,hidden=32,32"})
    assert (her.learner_config().batch_size, her.learner_config().hidden) == (64, (32, 32))
    run = tmp_path / "run"
    run.mkdir()
    (run / "config.json").write_text(json.dumps({**OLD_CONFIG, "run_dir": str(run)}))
    resumed, is_resume = config_from_cli(build_parser().parse_args(["--resume", str(run), "--iterations", "10"]))
    assert is_resume and resumed == dataclasses.replace(now, iterations=10, run_dir=str(run))
    for name, value in (("select_radius", 0.8), ("relabel", "settle"), ("held_share", 0.1)):
        with pytest.raises(InvalidConfig, match=name):  # held_share: only stop's held pairs are zero-action ones
            TrainConfig.from_json({**OLD_CONFIG, name: value})
    stop = TrainConfig.from_json({**OLD_CONFIG, "relabel": "stop", "held_share": 0.1})
    assert stop.held_share == 0.1 and identity(stop)["held_share"] == 0.1  # read back as it ran, and recorded


def test_a_her_run_recorded_before_mrls_defaults_reads_its_options_against_baselines_and_resumes():
    from splid_jax.learners.her.config import BASELINES
    from splid_jax.runtime.run_files import identity

    new = TrainConfig(env="push", algo="her", her_options="hidden=16,16,batch_size=32")
    old = {k: v for k, v in new.to_json().items() if k != "her_defaults"}  # config.json before the setting
    resumed = TrainConfig.from_json(old)
    her = resumed.learner_config()
    assert (her.hidden, her.batch_size) == ((16, 16), 32)  # the keys it gave
    assert all(getattr(her, k) == v for k, v in BASELINES.items() if k not in ("hidden", "batch_size"))
    # the checkpoint's identity as that run wrote it: its options as written, no her_defaults
    assert identity(resumed) == {k: v for k, v in identity(new).items() if k != "her_defaults"}
    assert identity(resumed)["her_options"] == "hidden=16,16,batch_size=32"
    assert TrainConfig.from_json(new.to_json()).learner_config() == new.learner_config()  # today's: mrl's defaults
    assert new.learner_config().layer_norm and not her.layer_norm
