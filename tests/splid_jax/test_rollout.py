import json

import jax
import mediapy
import mujoco
import numpy as np
import pytest

from envs import make as make_env
from splid_jax import rollout
from splid_jax.config import TrainConfig
from splid_jax.learners.splid.trainer import Trainer
from splid_jax.runtime import checkpoint
from splid_jax.train import env_settings
from splid_jax.train import main as train_main


@pytest.fixture(scope="module")
def point_run(tmp_path_factory):
    """A point run with checkpoints at iterations 2 and 4."""
    run_dir = tmp_path_factory.mktemp("point") / "run"
    assert train_main(["--env", "point", "--num-envs", "4", "--iterations", "4", "--eval-every", "2",
                       "--eval-episodes", "8", "--bc-steps", "5", "--hidden", "16", "--run-dir", str(run_dir),
                       "--quiet"]) == 0  # fmt: skip
    return run_dir


@pytest.fixture(scope="module")
def reach_run(tmp_path_factory):
    """A Reach run of 5-step episodes whose only checkpoint is the initial policy (no training compiled)."""
    run_dir = tmp_path_factory.mktemp("reach") / "run"
    cfg = TrainConfig(env="reach", env_options="max_episode_steps=5", iterations=1, eval_every=1, num_envs=2, horizon=2,
                      hidden=(8,), buffer_size=16, batch_size=4, run_dir=str(run_dir))  # fmt: skip
    env = cfg.make_env()
    checkpoint.save(run_dir, 0, Trainer(env, cfg).init(jax.random.PRNGKey(0)), {"env": env_settings(env)})
    (run_dir / "config.json").write_text(json.dumps(cfg.to_json()))
    return run_dir


def _files(d):
    return sorted(p.name for p in d.iterdir() if p.is_file())


def test_rollout_loads_the_newest_checkpoint_and_draws(point_run, capsys):
    assert rollout.main([str(point_run), "--episodes", "4"]) == 0
    out, err = capsys.readouterr()
    assert "iteration 4" in out and "success" in out
    assert "``" not in rollout.build_parser().format_help()
    assert "another version of the task" not in err
    png = (point_run / "rollout-4.png").read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n" and len(png) > 10_000


def test_rollout_step_picks_a_checkpoint_and_an_absent_one_lists_those_there(point_run, tmp_path, capsys):
    out = tmp_path / "at2.png"
    assert rollout.main([str(point_run), "--step", "2", "--episodes", "2", "--out", str(out)]) == 0
    assert "iteration 2" in capsys.readouterr().out and out.is_file()
    assert rollout.main([str(point_run), "--step", "3", "--out", str(tmp_path / "at3.png")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "step 3" in err and "[2, 4]" in err
    assert not (tmp_path / "at3.png").exists()


def test_rollout_refuses_to_overwrite_unless_asked(point_run, tmp_path, capsys):
    out = tmp_path / "mine.png"
    out.write_bytes(b"the user's figure")
    assert rollout.main([str(point_run), "--episodes", "2", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--overwrite" in err and str(out) in err
    assert out.read_bytes() == b"the user's figure"
    assert rollout.main([str(point_run), "--episodes", "2", "--out", str(out), "--overwrite"]) == 0
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize(
    "out, allowed",
    [("missing/dir/fig.png", "existing, writable directory"), ("fig.mp4", "image file name ending in")],
    ids=["missing-directory", "not-an-image-format"],
)
def test_rollout_bad_out_fails_before_any_work(tmp_path, capsys, monkeypatch, out, allowed):
    def no_work(*args, **kwargs):
        raise AssertionError("work started before --out was checked")

    monkeypatch.setattr(rollout, "load_config", no_work)
    assert rollout.main([str(tmp_path), "--out", str(tmp_path / out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "invalid --out " in err and allowed in err
    assert _files(tmp_path) == []


def test_rollout_of_a_missing_run_is_a_clear_error(tmp_path, capsys):
    assert rollout.main([str(tmp_path / "nothing")]) == 2
    assert "invalid RUN_DIR" in capsys.readouterr().err


def test_rollout_says_when_the_task_changed_since_training(tmp_path, capsys):
    import envs
    from splid_jax.train import run

    cfg = TrainConfig(env="point", num_envs=4, eval_episodes=4, bc_steps=2, batch_size=16, hidden=(8,),
                      eval_every=2, iterations=2, run_dir=str(tmp_path / "run"))  # fmt: skip
    run(cfg, env=envs.make("point", door_half_width=0.5), quiet=True)  # as if trained before a default changed
    assert rollout.main([cfg.run_dir, "--episodes", "4"]) == 0
    err = capsys.readouterr().err
    assert "another version of the task" in err and "door_half_width=0.5 then, 0.75 now" in err


class FakeRenderer:
    """Stands in for mujoco.Renderer: records the model and each pose it is asked to draw."""

    calls: list = []

    def __init__(self, model, height, width):
        self.model, self.shape, self.poses = model, (height, width, 3), []
        self.scene = mujoco.MjvScene(model, maxgeom=100)
        FakeRenderer.calls.append(self)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.closed = True

    def update_scene(self, data, camera=None):
        self.poses.append(data.qpos.copy())
        self.scene.ngeom = 0

    def render(self):
        return np.full(self.shape, 40 * len(self.poses) % 256, np.uint8)


@pytest.fixture
def fake_renderer(monkeypatch):
    FakeRenderer.calls = []
    monkeypatch.setattr(mujoco, "Renderer", FakeRenderer)
    return FakeRenderer


def test_render_frames_poses_the_model_at_each_state(fake_renderer):
    model = make_env("reach").mj_model
    qpos = np.array([[0.0, 0.0, 0.0], [0.01, 0.02, 0.03], [0.05, -0.02, 0.0]])
    frames = rollout.render_frames(model, qpos, np.zeros(3), np.ones(3), size=(24, 32))
    (renderer,) = fake_renderer.calls
    assert renderer.model is model and renderer.closed
    np.testing.assert_allclose(np.stack(renderer.poses), qpos)
    assert frames.shape == (3, 24, 32, 3) and renderer.scene.ngeom == 1  # the goal marker


@pytest.mark.parametrize("ffmpeg", [False, True], ids=["strip-without-ffmpeg", "mp4"])
def test_rollout_of_a_fetch_task_draws_its_frames(reach_run, fake_renderer, monkeypatch, capsys, ffmpeg):
    if ffmpeg and not mediapy.video_is_available():
        pytest.skip("ffmpeg is not on the PATH, so no MP4 can be written here")
    monkeypatch.setattr(mediapy, "video_is_available", lambda: ffmpeg)
    assert rollout.main([str(reach_run), "--episodes", "2", "--overwrite"]) == 0
    (renderer,) = fake_renderer.calls
    assert renderer.model is make_env("reach", max_episode_steps=5).mj_model  # built once, cached
    assert len(renderer.poses) == 6  # the start and 5 steps of episode 0
    out = capsys.readouterr().out
    frames = reach_run / ("rollout-0.mp4" if ffmpeg else "rollout-0-frames.png")
    assert str(frames) in out and frames.stat().st_size > 1000
    if ffmpeg:
        assert frames.read_bytes()[4:8] == b"ftyp"  # an MP4 container
    else:
        assert "no ffmpeg" in out


def test_rollout_without_offscreen_gl_says_so_in_one_line(reach_run, monkeypatch, capsys):
    def no_gl(*args, **kwargs):
        raise mujoco.FatalError("an OpenGL platform library has not been loaded into this process")

    monkeypatch.setattr(mujoco, "Renderer", no_gl)
    out = reach_run / "nogl.png"
    assert rollout.main([str(reach_run), "--episodes", "2", "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "offscreen rendering is unavailable" in printed and "MUJOCO_GL" in printed
    assert out.is_file() and not (reach_run / "nogl.mp4").exists() and not (reach_run / "nogl-frames.png").exists()


def test_render_frames_draws_the_gripper_moving():
    env = make_env("reach")
    home = np.array(env.layout.grip_home)
    qpos = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.1, 0.1, -0.1]])
    try:
        frames = rollout.render_frames(env.mj_model, qpos, home, home)
    except rollout.RenderingUnavailable as err:
        pytest.skip(f"{err}: set MUJOCO_GL=egl (or osmesa) to run this test")
    assert frames.shape == (3, 240, 320, 3) and frames.dtype == np.uint8
    assert frames[0].std() > 5  # a scene, not a blank image
    np.testing.assert_array_equal(frames[0], frames[1])
    assert (frames[2] != frames[0]).any(axis=-1).mean() > 0.01  # the gripper moved: over 1 % of the pixels


def test_paths_figure_has_a_title_and_a_legend():
    from types import SimpleNamespace

    ag = np.zeros((3, 2, 2))  # [T + 1, E, G]: two episodes of two steps
    states = SimpleNamespace(achieved_goal=ag, desired_goal=ag + 1, success=np.array([[0, 0], [0, 1], [0, 1]], bool))
    fig = rollout.paths_figure(make_env("point"), states, "point: iteration 4")
    assert fig.axes[0].get_title() == "point: iteration 4"
    (legend,) = fig.legends
    assert [t.get_text() for t in legend.get_texts()] == ["reached its goal", "did not", "start", "goal", "wall"]


def test_paths_figure_links_each_episodes_start_path_and_goal_by_colour():
    from types import SimpleNamespace

    from matplotlib.colors import to_rgba

    ag = np.stack([np.linspace(0, 1, 4), np.zeros(4)], -1)[:, None] + np.array([[0.0, 0.0], [0.0, 2.0]])[None]
    goal = np.broadcast_to(np.array([[1.0, 0.0], [3.0, 2.0]]), (4, 2, 2))
    success = np.array([[0, 0], [0, 0], [1, 0], [1, 0]], bool)  # the first reaches its goal, the second does not
    states = SimpleNamespace(achieved_goal=ag, desired_goal=goal, success=success)
    lines = rollout.paths_figure(make_env("point"), states, "t").axes[0].get_lines()
    assert len(lines) == 6  # path, start, goal per episode
    for e, (path, start, star) in enumerate(zip(lines[0::3], lines[1::3], lines[2::3], strict=True)):
        assert to_rgba(path.get_color()) == to_rgba(start.get_color()) == to_rgba(star.get_color())
        np.testing.assert_allclose(star.get_xydata()[0], goal[0, e])
        assert path.get_linestyle() == ("-" if e == 0 else "--")
    assert to_rgba(lines[0].get_color()) != to_rgba(lines[3].get_color())


@pytest.mark.parametrize(
    "algo,options",
    [
        ("her", {"her_options": "hidden=8,buffer_transitions=500,update_every=0,n_batches=2"}),
        ("es", {"es_options": "population=4"}),
    ],
)
def test_rollout_acts_as_the_evaluation_of_a_her_or_es_run(tmp_path, capsys, algo, options):
    """HER's actor and ES's search mean both sit at ``state.policy``; rollout rolls what the loop evaluates."""
    from splid_jax.common.evaluation import evaluate
    from splid_jax.learners.registry import make_algorithm

    run_dir = tmp_path / "run"
    cfg = TrainConfig(env="point", algo=algo, iterations=1, eval_every=1, hidden=(8,) if algo == "es" else None,
                      run_dir=str(run_dir), **options)  # fmt: skip
    env = make_env(cfg.env)
    algo_ = make_algorithm(cfg, env)
    state = algo_.init(jax.random.PRNGKey(1))
    checkpoint.save(run_dir, 0, state, {"env": env_settings(env)})
    (run_dir / "config.json").write_text(json.dumps(cfg.to_json()))

    _, loaded, pstate, step = rollout.load_policy(rollout.load_config(str(run_dir)))
    assert step == 0 and type(loaded).__name__ == algo.upper()
    states = rollout.rollout(env, loaded.policy, pstate.policy, jax.random.PRNGKey(3), 16)
    evaluated = evaluate(env, algo_.policy, state.policy, jax.random.PRNGKey(3), 16)
    succ = np.asarray(states.success[1:] & ~states.invalid[1:])
    assert succ.any(axis=0).mean() == pytest.approx(float(evaluated["eval_success"]))
    assert rollout.main([str(run_dir), "--episodes", "4"]) == 0
    assert "iteration 0" in capsys.readouterr().out


@pytest.mark.parametrize(
    "args,field",
    [(["--episodes", "100000000"], "episodes"), (["--seed", "-1"], "seed"), (["--seed", str(2**32)], "seed")],
)
def test_rollout_refuses_what_it_cannot_do_before_rolling_out(point_run, capsys, monkeypatch, args, field):
    monkeypatch.setattr(rollout, "rollout", lambda *a, **kw: pytest.fail("rolled out"))
    before = _files(point_run)
    assert rollout.main([str(point_run), *args]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and f"invalid --{field} " in err
    assert _files(point_run) == before


def test_rollout_of_a_run_in_a_read_only_directory_says_so_before_rolling_out(point_run, capsys, monkeypatch):
    import builtins

    real_open = builtins.open

    def read_only(path, mode="r", *a, **kw):  # the run directory refuses writes, as a read-only mount does
        if "w" in mode and str(path).startswith(str(point_run)):
            raise PermissionError(13, "Permission denied", str(path))
        return real_open(path, mode, *a, **kw)

    monkeypatch.setattr(builtins, "open", read_only)
    monkeypatch.setattr(rollout, "rollout", lambda *a, **kw: pytest.fail("rolled out"))
    assert rollout.main([str(point_run), "--episodes", "4", "--overwrite"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "invalid --out " in err and "writable" in err


def test_rollout_help_explains_run_dir_and_seed(capsys):
    with pytest.raises(SystemExit):
        rollout.main(["--help"])
    out = " ".join(capsys.readouterr().out.split())
    assert "RUN_DIR a run directory written by train" in out and "seed of the episodes' starts" in out


def test_rollout_of_an_unreadable_run_is_not_called_missing(tmp_path, capsys, monkeypatch):
    import os

    (tmp_path / "config.json").write_text("{}")
    real_access = os.access  # permissions that bar even root, as a read-only share does for others
    monkeypatch.setattr(os, "access", lambda p, m: not str(p).endswith("config.json") and real_access(p, m))
    assert rollout.main([str(tmp_path)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "whose config.json can be read (Permission denied)" in err


def test_rollout_of_a_sweep_member_rolls_its_slice_of_the_sweeps_checkpoint_out(tmp_path, capsys):
    cfg = TrainConfig(env="point", iterations=2, eval_every=2, num_envs=4, hidden=(16,), run_dir=str(tmp_path))
    env = cfg.make_env()
    init = Trainer(env, cfg).init
    stacked = jax.vmap(init)(jax.random.split(jax.random.PRNGKey(0), 2))
    checkpoint.save(tmp_path, 2, stacked, {"env": env_settings(env)})
    members = [{**cfg.to_json(), "seed": i, "run_dir": f"m{i}"} for i in range(2)]
    (tmp_path / "sweep.json").write_text(json.dumps({"config": cfg.to_json(), "members": members}))
    for m in members:
        (tmp_path / m["run_dir"]).mkdir()
        (tmp_path / m["run_dir"] / "config.json").write_text(json.dumps({**m, "run_dir": str(tmp_path / m["run_dir"])}))
    assert rollout.main([str(tmp_path / "m1"), "--episodes", "2"]) == 0
    assert "iteration 2" in capsys.readouterr().out and (tmp_path / "m1" / "rollout-2.png").is_file()
