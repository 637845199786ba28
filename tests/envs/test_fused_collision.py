"""MJX's plane-box and box-box contacts as one program per pair: MJX's contacts (as a set, up to MJX's float ties)
on random box pairs and on Push's states, the Pallas kernels the same functions lowered as one Triton call each,
and a scripted Push path as MJX's."""

from __future__ import annotations

import functools

import jax
import jax.numpy as jnp
import numpy as np
from mujoco.mjx._src import collision_convex, collision_driver, math, mesh
from mujoco.mjx._src.collision_types import GeomInfo

import envs
from envs import box_contacts, fused_collision
from envs.fetch.kernels import runs_as_kernel
from tests.helpers import needs_kernels, triton_calls_in_step


def _rotation(q):
    w, x, y, z = q / jnp.linalg.norm(q)
    return jnp.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                      [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                      [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])  # fmt: skip


def _pairs(n: int, seed: int = 0):
    """Box pairs near contact: tilted a little, face to face, and at random orientations."""
    rng = np.random.default_rng(seed)
    rows = []
    for i in range(n):
        q = [np.array([1.0, *rng.normal(0, 0.02, 3)]) for _ in range(2)] if i % 3 == 0 else (
            [np.array([1.0, 0, 0, 0]), np.array([1.0, 0, 0, rng.normal(0, 0.3)])] if i % 3 == 1
            else [rng.normal(size=4) for _ in range(2)])  # fmt: skip
        p2 = rng.normal(0, 0.1, 3)
        direction = rng.normal(size=3)
        p1 = p2 + direction / np.linalg.norm(direction) * rng.uniform(0.0, 0.06)
        rows.append((p1, _rotation(jnp.asarray(q[0])), rng.uniform(0.01, 0.04, 3),
                     p2, _rotation(jnp.asarray(q[1])), rng.uniform(0.01, 0.04, 3)))  # fmt: skip
    return [jnp.asarray(np.stack([np.asarray(r[k]) for r in rows]), jnp.float32) for k in range(6)]


def _mjx(p1, m1, s1, p2, m2, s2):
    infos = [mesh.box(GeomInfo(p1, m1, s1)), mesh.box(GeomInfo(p2, m2, s2))]
    axes = [jax.tree_util.tree_map(lambda x: None, i).replace(pos=0, mat=0, size=0, face=0, vert=0) for i in infos]

    def one(b1, b2):
        dist, pos, n = collision_convex._box_box(b1, b2)
        return dist, pos, jax.vmap(math.make_frame)(n)

    return jax.vmap(one, in_axes=axes)(*infos)


def _contacts(dist, pos, i):
    """Pair i's contacts in contact, as a set of rounded (x, y, z, dist)."""
    rows = np.concatenate([np.asarray(pos[i]), np.asarray(dist[i])[:, None]], axis=1).round(5)
    return {tuple(r) for r in rows if r[3] < 0}


def test_box_box_makes_mjxs_contacts():
    args = _pairs(90)
    want = jax.jit(_mjx)(*args)
    got = jax.jit(jax.vmap(box_contacts.box_box))(*args)
    np.testing.assert_allclose(got[2], want[2], atol=1e-5)  # the normal's frame: the same separating axis
    touching = np.asarray(want[0] < 0).any(axis=1)
    assert touching.sum() > 50
    same = [_contacts(*got[:2], i) == _contacts(*want[:2], i) for i in range(len(touching))]
    assert sum(same) >= 0.95 * len(same), [i for i, ok in enumerate(same) if not ok]


def test_kernels_are_the_functions_and_lower_as_one_triton_call_each():
    args = _pairs(12, seed=1)
    plane = (args[3], args[4], *args[:3])  # the second box's frame as a plane, the first box on it
    cases = [
        (box_contacts.box_box, fused_collision.kernel_box_box, args),
        (box_contacts.plane_box, fused_collision.kernel_plane_box, plane),
    ]
    for function, kernel_fn, inputs in cases:
        plain = jax.jit(jax.vmap(function))(*inputs)
        kernel = jax.jit(jax.vmap(functools.partial(kernel_fn, interpret=True)))(*inputs)
        assert int((np.asarray(plain[0]) < 0).sum()) > 0
        for i in range(12):
            assert _contacts(*kernel[:2], i) == _contacts(*plain[:2], i)
        lowered = jax.jit(jax.vmap(kernel_fn)).trace(*inputs).lower(lowering_platforms=("cuda",))
        assert lowered.as_text().count("xla.gpu.triton") == 1


@functools.cache
def _scripted_run(fetch, **options):
    """The task and its physics after each of the first 8 steps of 8 Push envs under the scripted pusher, from
    FetchEpisodes' program (no action added to the script's): one compiled program per choice of ``options``, read
    by the tests below. The library's Cholesky (the same physics to float rounding, both paths alike) keeps the
    programs' compiles short, and the task without options is test_small_cholesky's (conftest puts the files on
    one worker)."""
    env = envs.make("push", cholesky="library", **options)
    _, _, path = fetch.run(env, jnp.zeros((fetch.T, fetch.B, env.action_size)), w=1.0)
    return env, jax.tree_util.tree_map(lambda x: x[:8], path.physics)


def test_push_states_get_mjxs_contacts(fetch):
    env, physics = _scripted_run(fetch)
    contacts = functools.partial(fused_collision.contacts, env)
    mjxs, ours = (jax.jit(jax.vmap(functools.partial(contacts, fused=f))) for f in (False, True))
    touching = 0
    for k in (3, 7):  # after the fourth step, and the eighth: the finger block meets the cube from the seventh on
        state = jax.tree_util.tree_map(lambda x, k=k: x[k], physics)
        want, got = mjxs(state), ours(state)
        np.testing.assert_allclose(got[2], want[2], atol=1e-5)
        for e in range(8):
            assert _contacts(*got[:2], e) == _contacts(*want[:2], e)
        touching += int((np.asarray(want[0]) < 0).sum())
    assert touching > 50


def test_push_path_follows_mjxs(fetch):
    # the finger block meets the cube from the seventh step on: without its contacts the path parts there by 0.017;
    # from the eighth, contact amplifies float rounding (to 2e-4 in a cube's orientation with the library's Cholesky)
    base, fused = (np.asarray(_scripted_run(fetch, **options)[1].qpos) for options in ({}, {"collision": "fused"}))
    assert np.isfinite(fused).all()
    np.testing.assert_allclose(fused[:7], base[:7], atol=1e-5)
    np.testing.assert_allclose(fused[7:], base[7:], atol=1e-3)


def test_the_driver_is_given_the_plane_box_and_box_box_groups_alone():
    groups = fused_collision.groups()
    assert set(groups) == {(0, 6), (6, 6)} and {g.ncon for g in groups.values()} == {4}  # four contacts a pair
    assert set(groups) <= set(collision_driver._COLLISION_FUNC)
    assert [runs_as_kernel("gpu-fused", b) for b in ("gpu", "cpu")] == [True, False]


@needs_kernels
def test_push_collides_boxes_in_kernels_on_a_gpu_by_default():
    env = envs.make("push", substeps=1)
    assert triton_calls_in_step(env) == (0, 3)  # plane-box and box-box contacts, the constraint solve
