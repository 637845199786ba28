"""Where one MJX substep of a Fetch-style task spends its time: each stage of ``mjx.step`` timed
alone on a batch of states from real episodes, next to the whole step and to whole steps with parts
of the constraint pipeline switched off.

Each timed program applies its stage ``--repeat-stage`` times in a ``fori_loop`` (the output feeding
the next application, so nothing is hoisted) to a vmapped batch; the median of ``--repeats`` timed
calls (``block_until_ready``, after a warm-up call) divided by that count gives the time per
application. The states come from a short random-action rollout after reset, with the gripper driven
into the object half of the time, so that contacts are as frequent as in training.

    python experiments/bench_physics_parts.py --task push --batch 65536
    python experiments/bench_physics_parts.py --task push --batch 64 --repeats 2   # CPU smoke test
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import sys
import time
from pathlib import Path

import jax
import jax.numpy as jnp

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

with contextlib.redirect_stdout(io.StringIO()):  # mujoco.mjx prints a note about warp on import
    from mujoco import mjx

from bench_splid import timed as timed_calls  # noqa: E402

import envs  # noqa: E402
from envs import small_cholesky  # noqa: E402
from envs.base import step_batch  # noqa: E402

STAGES = {
    # the stages of mjx.step in the order it runs them (forward, then the integrator)
    "fwd_position (kinematics, com, crb, factor_m, collision, make_constraint, transmission)": mjx.fwd_position,
    "  of which collision": mjx.collision,
    "  of which make_constraint": mjx.make_constraint,
    "fwd_velocity (passive, bias forces)": mjx.fwd_velocity,
    "fwd_actuation": mjx.fwd_actuation,
    "fwd_acceleration": mjx.fwd_acceleration,
    "solve (Newton)": mjx.solve,
    "euler (implicit damping)": mjx.euler,
}


def sample_data(env, batch: int, steps: int, key):
    """The physics states of a batch after ``steps`` control steps: random actions, or (every other env)
    actions towards the object, so that finger-object contacts occur."""
    states = jax.vmap(env.reset)(jax.random.split(key, batch))

    def one(s, k):
        obs = s.obs
        towards = jnp.clip(20.0 * obs[:, 6:9], -1.0, 1.0)  # obs[6:9]: object relative to the grip
        random = jax.random.uniform(k, (batch, env.action_size), minval=-1.0, maxval=1.0)
        mix = jnp.where((jnp.arange(batch) % 2 == 0)[:, None], towards, random[:, :3])
        action = random.at[:, :3].set(mix)
        return step_batch(env, s, action), None

    states, _ = jax.lax.scan(one, states, jax.random.split(jax.random.fold_in(key, 1), steps))
    return states.physics


def data_for(model, phys):
    """The batch as ``mjx.step`` of ``model`` sees it: state fields set, derived fields filled."""

    def one(p):
        d = mjx.make_data(model).replace(
            qpos=p.qpos, qvel=p.qvel, ctrl=p.ctrl, time=p.time, qacc_warmstart=p.qacc_warmstart
        )
        return mjx.forward(model, d)

    return jax.jit(jax.vmap(one))(phys)


def timed(fn, model, data, times: int, repeats: int, unrolled: bool = True) -> dict:
    """Per-application time of ``fn``; MJX's small Cholesky solves unrolled as the tasks run them
    (``envs/small_cholesky.py``) unless ``unrolled`` is False."""

    def prog(d):
        with small_cholesky.unrolled_in_mjx(unrolled):
            return jax.lax.fori_loop(0, times, lambda _, x: jax.vmap(lambda y: fn(model, y))(x), d)

    stats, _ = timed_calls(jax.jit(prog), data, repeats=repeats)
    return {"per_application_ms": 1e3 * stats["median_s"] / times, "compile_s": stats["compile_s"]}


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--task", default="push", choices=["reach", "push", "slide", "pick_and_place"])
    p.add_argument("--batch", type=int, default=65536)
    p.add_argument("--rollout-steps", type=int, default=10, help="control steps before the states are taken")
    p.add_argument("--repeat-stage", type=int, default=20, help="applications per timed program")
    p.add_argument("--repeats", type=int, default=5)
    p.add_argument("--out", type=Path, default=None)
    a = p.parse_args(argv)
    if min(a.batch, a.repeat_stage, a.repeats) < 1 or a.rollout_steps < 0:
        p.error("--batch, --repeat-stage and --repeats must be >= 1, --rollout-steps >= 0")
    env = envs.make(a.task)
    model = env.mjx_model
    dev = jax.devices()[0]
    print(f"device {dev.device_kind} ({jax.default_backend()}), jax {jax.__version__}, {a.task}, batch {a.batch}")
    phys = sample_data(env, a.batch, a.rollout_steps, jax.random.PRNGKey(0))
    data = data_for(model, phys)
    dist = data._impl.contact.dist  # [batch, contact slots]
    touching = float(jnp.mean(jnp.sum(dist < 0, axis=-1)))
    rows_efc = data._impl.efc_J.shape[-2]
    print(f"contact slots {dist.shape[-1]} ({touching:.2f} penetrating per env), constraint rows {rows_efc}")

    rows = []
    whole = {  # name -> (model, whether MJX's small Cholesky solves run unrolled)
        "mjx.step (one substep)": (model, True),
        "mjx.step, jax.scipy.linalg Cholesky": (model, False),
        "mjx.step, contacts off (DisableBit.CONTACT)": (
            model.replace(opt=model.opt.replace(disableflags=model.opt.disableflags | mjx.DisableBit.CONTACT)),
            True,
        ),
        "mjx.step, all constraints off (DisableBit.CONSTRAINT)": (
            model.replace(opt=model.opt.replace(disableflags=model.opt.disableflags | mjx.DisableBit.CONSTRAINT)),
            True,
        ),
        "mjx.step, Newton 1 iteration / 1 line search": (
            model.replace(opt=model.opt.replace(iterations=1, ls_iterations=1)),
            True,
        ),
    }
    for name, (m, unrolled) in whole.items():
        m_data = data if m is model else data_for(m, phys)
        r = timed(mjx.step, m, m_data, a.repeat_stage, a.repeats, unrolled=unrolled)
        rows.append({"part": name, **r})
        print(f"{name:90s} {r['per_application_ms']:8.3f} ms  (compile {r['compile_s']:.1f} s)")
    for name, fn in STAGES.items():
        r = timed(fn, model, data, a.repeat_stage, a.repeats)
        rows.append({"part": name, **r})
        print(f"{name:90s} {r['per_application_ms']:8.3f} ms  (compile {r['compile_s']:.1f} s)")
    step_ms = rows[0]["per_application_ms"]
    print(f"\n| part | ms per substep at batch {a.batch} | share of mjx.step |\n|---|---:|---:|")
    for r in rows:
        print(f"| {r['part'].strip()} | {r['per_application_ms']:.3f} | {r['per_application_ms'] / step_ms:.0%} |")
    if a.out:
        meta = {"device": dev.device_kind, "backend": jax.default_backend(), "jax": jax.__version__,
                "task": a.task, "batch": a.batch, "date": time.strftime("%Y-%m-%d"), "argv": sys.argv[1:]}  # fmt: skip
        a.out.write_text(json.dumps({"meta": meta, "rows": rows}, indent=1))
        print(f"wrote {a.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
