"""``python -m splid_jax.rollout RUN_DIR``: roll a run's deterministic policy out, report its success and
draw the episodes: their paths on the task's map, and for the MuJoCo tasks a video of one episode
through MuJoCo's offscreen renderer (headless: set MUJOCO_GL=egl, or osmesa without a GPU)."""

from __future__ import annotations

from splid_jax.cli import check_environment, exit_with, quiet_interrupts, run_main

if __name__ == "__main__":  # a signal while it loads or works ends the process with one line, no traceback
    quiet_interrupts("")
    check_environment()

import argparse  # noqa: E402
import json  # noqa: E402
import os  # noqa: E402
import sys  # noqa: E402
import warnings  # noqa: E402

import jax  # noqa: E402
import jax.numpy as jnp  # noqa: E402
import numpy as np  # noqa: E402

from envs.base import step_batch  # noqa: E402
from splid_jax.cli import Parser, add_compile_cache_flag, flag_error, use_compile_cache  # noqa: E402
from splid_jax.common.errors import InvalidConfig  # noqa: E402
from splid_jax.common.images import save_figure  # noqa: E402
from splid_jax.common.paths import unreadable  # noqa: E402
from splid_jax.common.subgoals import steered  # noqa: E402
from splid_jax.config import TrainConfig  # noqa: E402
from splid_jax.learners.registry import make_algorithm  # noqa: E402
from splid_jax.runtime import checkpoint  # noqa: E402
from splid_jax.runtime.memory import device_memory, gigabytes, nbytes  # noqa: E402
from splid_jax.runtime.run_files import note_task_changes  # noqa: E402

DESCRIPTION = (
    "Roll a run's deterministic policy out, report its success and draw the episodes: their paths, "
    "and for the MuJoCo tasks a video of one episode (headless: set MUJOCO_GL=egl, or osmesa without a GPU)."
)
STRIP_FRAMES = 6  # frames of the image strip drawn in place of the video where ffmpeg is absent


class RenderingUnavailable(RuntimeError):
    """No offscreen OpenGL context can be made in this process."""


def load_config(run_dir: str) -> TrainConfig:
    path = os.path.join(run_dir, "config.json")
    why = unreadable(run_dir) or unreadable(path)
    if why:
        raise InvalidConfig("run_dir", run_dir, f"a run directory whose config.json can be read ({why})")
    if not os.path.isfile(path):
        raise InvalidConfig("run_dir", run_dir, "a run directory holding config.json")
    try:
        with open(path) as fh:
            saved = json.load(fh)
        if not isinstance(saved, dict):
            raise TypeError("not an object")
        return TrainConfig.from_json(saved, run_dir=run_dir)
    except (ValueError, TypeError):  # not UTF-8, not JSON, not an object of train's fields
        raise InvalidConfig("run_dir", run_dir, "a run directory whose config.json train wrote") from None


def load_policy(cfg: TrainConfig, step: int | None = None):
    """The task, the run's algorithm and its trained state at checkpoint ``step`` (default: the newest).
    Every algorithm acts through ``algo.policy`` with the ``networks.PolicyState`` at ``state.policy``:
    SPLID's, GCSL's and PCHID's cloned policy, HER's actor, ES's search mean."""
    env = cfg.make_env()
    trainer = make_algorithm(cfg, env)
    like = jax.eval_shape(trainer.init, jax.random.PRNGKey(0))
    step, state, meta = checkpoint.restore(cfg.run_dir, like, step=step)
    note_task_changes(cfg.run_dir, meta["env"], env)
    return env, trainer, state, step


def sweep_member(run_dir: str) -> tuple[str, int, int] | None:
    """(sweep directory, member index, members) when ``run_dir`` is a member of a sweep, whose
    checkpoints the sweep directory holds, stacked over members."""
    parent = os.path.dirname(os.path.abspath(run_dir))
    path = os.path.join(parent, "sweep.json")
    if not os.path.isfile(path):
        return None
    try:
        with open(path) as fh:
            names = [m.get("run_dir") for m in json.load(fh).get("members", [])]
    except (OSError, ValueError, AttributeError, TypeError):  # unreadable, not UTF-8, not JSON, not a sweep's
        raise checkpoint.CheckpointError(f"{path} is not a sweep.json that sweep wrote") from None
    name = os.path.basename(os.path.abspath(run_dir))
    return (parent, names.index(name), len(names)) if name in names else None


def restore_sweep(directory: str, env=None, step: int | None = None):
    """(task, algorithm, state stacked over members, step, checkpoint record) of the sweep in ``directory``,
    laid out as the sweep's own config builds it; ``env``: the task to build the algorithm on (default: the
    sweep's own)."""
    with open(os.path.join(directory, "sweep.json")) as fh:
        saved = json.load(fh)
    cfg = TrainConfig.from_json(saved["config"], run_dir=directory)
    env = cfg.make_env() if env is None else env
    trainer = make_algorithm(cfg, env)
    members = len(saved.get("members", []))
    like = jax.eval_shape(jax.vmap(trainer.init), jax.random.split(jax.random.PRNGKey(0), members))
    step, state, meta = checkpoint.restore(directory, like, step=step)
    return env, trainer, state, step, meta


def restore_member(cfg: TrainConfig, sweep: tuple[str, int, int], step: int | None):
    """A sweep member's task, algorithm, state and step, sliced out of the sweep's stacked checkpoint
    (members differ only in data, not in shapes)."""
    directory, index, _ = sweep
    env = cfg.make_env()  # the member's task, with any changed fields
    env, trainer, state, step, meta = restore_sweep(directory, env, step)
    note_task_changes(cfg.run_dir, meta.get("env", {}), env)
    return env, trainer, jax.tree.map(lambda x: x[index], state), step


def load_trained(cfg: TrainConfig, step: int | None = None):
    """``load_policy`` of a run of train, or of a sweep member (``cfg.run_dir``), whose state is its slice
    of the sweep's checkpoint."""
    if checkpoint.latest_step(cfg.run_dir) is not None:
        return load_policy(cfg, step)
    sweep = sweep_member(cfg.run_dir)
    if sweep is None or checkpoint.latest_step(sweep[0]) is None:
        where = f"{cfg.run_dir}/checkpoints"
        raise checkpoint.CheckpointError(f"{cfg.run_dir} holds no checkpoint (train writes them in {where})")
    return restore_member(cfg, sweep, step)


def rollout(env, policy, pstate, key, episodes: int):
    """Episodes of the deterministic ``policy`` (``act(pstate, obs, goal)``) from the task's standard starts:
    the states [T + 1, E]."""
    env = env.evaluation_task()

    def one_step(s, _):
        nxt = step_batch(env, s, policy.act(pstate, s.obs, s.desired_goal))
        return nxt, nxt

    start = jax.vmap(env.reset)(jax.random.split(key, episodes))
    _, later = jax.lax.scan(one_step, start, None, length=env.episode_length)
    return jax.tree_util.tree_map(lambda a, b: jnp.concatenate([a[None], b]), start, later)


def paths_figure(env, states, title: str):
    """The episodes' achieved-goal paths in x-y: each episode's start, path and goal in a colour of its own, the
    path solid where the goal was reached and dashed where not."""
    from matplotlib.figure import Figure
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch, Rectangle

    ag = np.asarray(states.achieved_goal)  # [T + 1, E, G]
    goal = np.asarray(states.desired_goal[0])
    succ = np.asarray(states.success[1:]).any(axis=0)
    fig = Figure(figsize=(6, 6.6))
    ax = fig.add_subplot()
    legend = [
        Line2D([], [], color="0.3", lw=1.2, label="reached its goal"),
        Line2D([], [], color="0.3", lw=1.2, ls="--", label="did not"),
        Line2D([], [], ls="", marker="o", color="0.3", ms=4, label="start"),
        Line2D([], [], ls="", marker="*", color="0.3", mec="k", ms=10, label="goal"),
    ]
    if hasattr(env, "boxes"):  # the point task: draw its walls
        for x0, x1, y0, y1 in np.asarray(env.boxes):
            ax.add_patch(Rectangle((x0, y0), x1 - x0, y1 - y0, color="0.5"))
        ax.set_xlim(-5, 5)
        ax.set_ylim(-5, 5)
        legend.append(Patch(color="0.5", label="wall"))
    palette = [f"C{i}" for i in range(10)]
    for e in range(ag.shape[1]):
        colour = palette[e % len(palette)]
        ax.plot(ag[:, e, 0], ag[:, e, 1], "-" if succ[e] else "--", color=colour, lw=1.2)
        ax.plot(ag[0, e, 0], ag[0, e, 1], "o", color=colour, ms=4)
        ax.plot(goal[e, 0], goal[e, 1], "*", color=colour, mec="k", mew=0.6, ms=10)
    ax.set_aspect("equal")
    ax.set_title(title)
    ax.set_xlabel("x of the achieved goal")
    ax.set_ylabel("y")
    fig.legend(handles=legend, loc="lower center", ncols=len(legend), fontsize="small", frameon=False)
    fig.subplots_adjust(bottom=0.14)
    return fig


def _camera(mujoco, start: np.ndarray, goal: np.ndarray):
    """A free camera framing the episode's start and goal."""
    cam = mujoco.MjvCamera()
    cam.type = mujoco.mjtCamera.mjCAMERA_FREE
    cam.lookat[:] = (start + goal) / 2
    cam.distance = 0.6 + 1.5 * float(np.linalg.norm(goal - start))
    cam.azimuth, cam.elevation = 150.0, -25.0
    return cam


def render_frames(model, qpos: np.ndarray, start: np.ndarray, goal: np.ndarray, size=(240, 320)) -> np.ndarray:
    """Frames [T, H, W, 3] of ``model`` posed at each row of ``qpos`` [T, nq], the goal drawn as a
    green sphere. Raises ``RenderingUnavailable`` where no offscreen OpenGL context can be made."""
    import mujoco

    gl = os.environ.get("MUJOCO_GL", "")
    if not hasattr(mujoco, "Renderer"):  # the MUJOCO_GL backend's library failed to load
        raise RenderingUnavailable(f"MuJoCo has no renderer with MUJOCO_GL={gl!r}")
    try:
        with warnings.catch_warnings():  # GLFW warns before failing without a display; one line says it below
            warnings.simplefilter("ignore")
            renderer = mujoco.Renderer(model, *size)
    except (mujoco.FatalError, RuntimeError) as err:  # GLFW without a display, EGL/OSMesa without a device
        raise RenderingUnavailable(f"no OpenGL context with MUJOCO_GL={gl!r}") from err
    data = mujoco.MjData(model)
    cam = _camera(mujoco, np.asarray(start, np.float64), np.asarray(goal, np.float64))
    green = np.array([0.1, 0.8, 0.1, 0.6], np.float32)
    frames = []
    with renderer:
        for q in qpos:
            data.qpos[:] = q
            mujoco.mj_forward(model, data)
            renderer.update_scene(data, camera=cam)
            scene = renderer.scene
            if scene.ngeom < scene.maxgeom:
                geom = scene.geoms[scene.ngeom]
                mujoco.mjv_initGeom(geom, mujoco.mjtGeom.mjGEOM_SPHERE, np.array([0.02, 0, 0]), goal, np.eye(3).ravel(),
                                    green)  # fmt: skip
                scene.ngeom += 1
            frames.append(renderer.render())
    return np.stack(frames)


def write_strip(frames: np.ndarray, out: str, title: str) -> None:
    from matplotlib.figure import Figure

    picks = np.linspace(0, len(frames) - 1, min(STRIP_FRAMES, len(frames))).astype(int)
    fig = Figure(figsize=(3 * len(picks), 2.9))
    for i, t in enumerate(picks):
        ax = fig.add_subplot(1, len(picks), i + 1)
        ax.imshow(frames[t])
        ax.set_title(f"step {t}")
        ax.axis("off")
    fig.suptitle(title)
    fig.savefig(out, dpi=100, bbox_inches="tight")


def _outputs(out: str, video: bool) -> tuple[str, str]:
    """The paths figure and the episode's video (or, without ffmpeg, its image strip)."""
    stem = os.path.splitext(out)[0]
    return out, stem + (".mp4" if video else "-frames.png")


def _check_out(out: str) -> None:
    """Before any work: the figure's directory exists and is writable, and matplotlib knows its format."""
    from matplotlib.figure import Figure

    formats = Figure().canvas.get_supported_filetypes()
    ext = os.path.splitext(out)[1].lstrip(".").lower()
    if ext not in formats:
        raise InvalidConfig("out", out, "an image file name ending in ." + ", .".join(sorted(formats)))
    folder = os.path.dirname(out) or "."
    if not os.path.isdir(folder) or not os.access(folder, os.W_OK | os.X_OK):
        raise InvalidConfig("out", out, "a file in an existing, writable directory")


def _check_folder_writable(path: str) -> None:
    """A file made and removed beside ``path``: a read-only run directory fails here, not after the rollout."""
    probe = os.path.join(os.path.dirname(path) or ".", f".write-test-{os.getpid()}")
    try:
        with open(probe, "w") as fh:
            fh.write("x")
        os.remove(probe)
    except OSError as e:
        allowed = f"a file in a writable directory ({e.strerror}; pass --out elsewhere)"
        raise InvalidConfig("out", path, allowed) from None


def check_fits(env, episodes: int, device=None) -> None:
    """The episodes' states, [T + 1, E] twice (the scan's and their concatenation), against the
    device's memory: too many episodes are refused with the most that fit."""
    per = sum(nbytes(x) for x in jax.tree.leaves(jax.eval_shape(env.reset, jax.random.PRNGKey(0))))
    per_episode = 2 * per * (env.episode_length + 1)
    limit, source = device_memory(device or jax.devices()[0])
    if episodes * per_episode > limit:
        need = gigabytes(episodes * per_episode)
        allowed = f"at most {limit // per_episode} here (they need {need}; {source} is {gigabytes(limit)})"
        raise InvalidConfig("episodes", episodes, allowed)


def build_parser() -> argparse.ArgumentParser:
    p = Parser(prog="python -m splid_jax.rollout", description=DESCRIPTION)
    p.add_argument(
        "run_dir", metavar="RUN_DIR", help="a run directory written by train (or a sweep's member directory)"
    )
    p.add_argument("--step", type=int, default=None, help="checkpoint (iteration) to load (default: the newest)")
    p.add_argument("--episodes", type=int, default=16, help="episodes to roll out (default: 16)")
    p.add_argument(
        "--seed", type=int, default=123, help="seed of the episodes' starts and goals, in [0, 2**32) (default: 123)"
    )
    p.add_argument(
        "--out",
        default=None,
        metavar="FILE.png",
        help="figure of the paths; the video goes beside it as FILE.mp4 (default: RUN_DIR/rollout-STEP.png)",
    )
    p.add_argument("--overwrite", action="store_true", help="replace output files that already exist")
    add_compile_cache_flag(p)
    return p


def main(argv: list[str] | None = None) -> int:
    import mediapy

    p = build_parser()
    a = p.parse_args(argv)
    use_compile_cache(a.compile_cache)
    video = mediapy.video_is_available()  # ffmpeg on the PATH
    try:
        if a.episodes < 1:
            raise InvalidConfig("episodes", a.episodes, "an integer >= 1")
        if not 0 <= a.seed < 2**32:
            raise InvalidConfig("seed", a.seed, "an integer in [0, 2**32)")
        if a.out is not None:
            _check_out(a.out)
        cfg = load_config(a.run_dir)
        env, trainer, state, step = load_trained(cfg, a.step)
        figure, frames_out = _outputs(a.out or os.path.join(a.run_dir, f"rollout-{step}.png"), video)
        check_fits(env, a.episodes)
        _check_folder_writable(figure)
        mujoco_task = hasattr(env, "mj_model")
        for path in (figure, frames_out) if mujoco_task else (figure,):
            if os.path.exists(path) and not a.overwrite:
                raise InvalidConfig("out", path, "a file that does not exist yet (or pass --overwrite)")
    except (InvalidConfig, checkpoint.CheckpointError) as err:
        print(f"{p.prog}: error: {flag_error(err, p)}", file=sys.stderr)
        return 2
    policy = steered(trainer.policy, env, cfg.eval_subgoal_reach)  # as the run's evaluations acted
    states = jax.jit(lambda ps, k: rollout(env, policy, ps, k, a.episodes))(state.policy, jax.random.PRNGKey(a.seed))
    succ = np.asarray(states.success[1:] & ~states.invalid[1:])
    print(
        f"{a.run_dir} (iteration {step}): success {succ.any(axis=0).mean():.3f} at any step, "
        f"{succ[-1].mean():.3f} at the final step, over {a.episodes} episodes"
    )
    title = f"{cfg.env}: iteration {step}"
    paths = f"{title}, {a.episodes} episodes, success {succ.any(axis=0).mean():.2f} at any step"
    save_figure(paths_figure(env, states, paths), figure, dpi=110, bbox_inches="tight")
    print(f"paths: {figure}")
    if not mujoco_task:
        return 0
    try:
        frames = render_frames(
            env.mj_model,
            np.asarray(states.physics.qpos[:, 0]),
            np.asarray(states.achieved_goal[0, 0]),
            np.asarray(states.desired_goal[0, 0]),
        )
    except RenderingUnavailable as err:
        print(f"frames: not drawn, offscreen rendering is unavailable here ({err}); try MUJOCO_GL=egl or osmesa")
        return 0
    if video:
        mediapy.write_video(frames_out, frames, fps=round(1 / env.dt))
        print(f"video of episode 0: {frames_out}")
    else:
        write_strip(frames, frames_out, f"{title}, episode 0")
        print(f"frames of episode 0: {frames_out} (an image strip: no ffmpeg on the PATH for a video)")
    return 0


if __name__ == "__main__":
    exit_with(run_main(main))
