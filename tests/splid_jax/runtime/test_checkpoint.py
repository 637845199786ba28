import os
import signal
import subprocess
import sys
import textwrap
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np
import optax
import pytest
from flax import struct

from splid_jax.runtime import checkpoint as ck

REPO = Path(__file__).resolve().parents[2]
META = {"env": "point_fourrooms", "select": True, "seed": 3, "lr": 3e-4, "net": {"width": 256, "depth": 2}}


@struct.dataclass
class Buffer:
    obs: jax.Array
    goal: jax.Array
    done: jax.Array
    size: jax.Array


@struct.dataclass
class State:
    params: dict
    opt_state: optax.OptState
    buffer: Buffer
    key: jax.Array
    step: jax.Array
    episodes: int


def make_state(seed: int = 0, obs_shape=(1024, 5), tx=None) -> State:
    rng = np.random.default_rng(seed)
    params = {
        "dense": {"kernel": jnp.asarray(rng.normal(size=(5, 8)), jnp.float32), "bias": jnp.zeros(8, jnp.float32)},
        "head": jnp.asarray(rng.normal(size=(8, 2)), jnp.float32),
    }
    tx = tx or optax.adam(1e-3)
    opt_state = tx.init(params)
    for _ in range(3):  # non-trivial moments and count
        grads = jax.tree.map(lambda p: jnp.asarray(rng.normal(size=p.shape), p.dtype), params)
        updates, opt_state = tx.update(grads, opt_state, params)
        params = optax.apply_updates(params, updates)
    obs = rng.normal(size=obs_shape).astype(np.float32)
    obs.flat[:4] = [np.nan, -0.0, np.inf, np.float32(1e-45)]  # bit patterns == would not distinguish
    buffer = Buffer(
        obs=jnp.asarray(obs),
        goal=jnp.asarray(rng.integers(-(2**31), 2**31 - 1, size=(64,), dtype=np.int32)),
        done=jnp.asarray(rng.random(64) < 0.3),
        size=jnp.asarray(rng.integers(0, 2**32 - 1, dtype=np.uint32)),
    )
    return State(params, opt_state, buffer, jax.random.PRNGKey(seed), jnp.int32(17 + seed), 5 + seed)


def assert_bitwise_equal(a, b):
    la, lb = jax.tree.leaves(a), jax.tree.leaves(b)
    assert jax.tree.structure(a) == jax.tree.structure(b)
    for x, y in zip(la, lb, strict=True):
        x, y = np.asarray(x), np.asarray(y)
        assert x.dtype == y.dtype and x.shape == y.shape
        assert x.tobytes() == y.tobytes()


def test_round_trip_is_bitwise(tmp_path):
    state = make_state(1)
    assert ck.save(tmp_path, 10, state, META)
    step, restored, meta = ck.restore(tmp_path, make_state(0), expect_meta=META)
    assert step == 10 and meta == META
    assert_bitwise_equal(restored, state)
    assert isinstance(restored, State) and isinstance(restored.buffer, Buffer)
    assert type(restored.episodes) is int
    assert restored.buffer.size.dtype == jnp.uint32 and restored.key.dtype == jnp.uint32

    # An abstract template works too; the Python int comes back as a 0-d int32 array.
    step, abstract_restored, _ = ck.restore(tmp_path, jax.eval_shape(lambda: make_state(0)))
    assert int(abstract_restored.episodes) == state.episodes
    assert_bitwise_equal(abstract_restored.replace(episodes=0), state.replace(episodes=0))


def test_a_checkpoint_saved_on_another_machines_device_restores_here(tmp_path):
    """A GPU run's checkpoint names its device (cuda:0) in the saved shardings; an abstract template, as the
    evaluation and export tools build, restores it onto this machine's device."""
    state = make_state(2)
    assert ck.save(tmp_path, 10, state, META)
    (sharding,) = ck.checkpoint_dir(tmp_path).glob("10/*/_sharding")
    text = sharding.read_text()
    here = jax.local_devices()[0]
    assert text.count(f'\\"{here}\\"') > 0
    sharding.write_text(text.replace(f'\\"{here}\\"', '\\"cuda:0\\"'))
    _, restored, _ = ck.restore(tmp_path, jax.eval_shape(lambda: make_state(0)))
    assert_bitwise_equal(restored.replace(episodes=0), state.replace(episodes=0))
    assert all(x.devices() == {here} for x in jax.tree.leaves(restored))


def test_latest_step_and_max_to_keep(tmp_path):
    assert ck.latest_step(tmp_path) is None
    for step in range(1, 6):
        assert ck.save(tmp_path, step * 100, make_state(step), META)
    assert ck.latest_step(tmp_path) == 500
    assert sorted(int(p.name) for p in ck.checkpoint_dir(tmp_path).iterdir()) == [300, 400, 500]
    step, state, _ = ck.restore(tmp_path, make_state(0), step=300)
    assert step == 300
    assert_bitwise_equal(state, make_state(3))
    with pytest.raises(ck.CheckpointError, match=r"no checkpoint for step 100 .*\[300, 400, 500\]"):
        ck.restore(tmp_path, make_state(0), step=100)
    assert ck.save(tmp_path, 500, make_state(9), META) is False  # same step: kept as is
    assert_bitwise_equal(ck.restore(tmp_path, make_state(0))[1], make_state(5))
    with pytest.raises(ck.CheckpointError, match="newer step 500"):
        ck.save(tmp_path, 200, make_state(2), META)


def test_missing_checkpoint(tmp_path):
    with pytest.raises(ck.CheckpointError, match="no checkpoint"):
        ck.restore(tmp_path, make_state(0))
    ck.checkpoint_dir(tmp_path).mkdir()
    with pytest.raises(ck.CheckpointError, match="no checkpoint"):
        ck.restore(tmp_path, make_state(0))


@pytest.mark.parametrize(
    "like, pattern",
    [
        (
            make_state(0, obs_shape=(512, 5)),
            r"'buffer\.obs' is \(1024, 5\) float32 in the checkpoint but \(512, 5\) float32",
        ),
        (
            make_state(0).replace(buffer=make_state(0).buffer.replace(goal=jnp.zeros(64, jnp.float32))),
            r"'buffer\.goal' is \(64,\) int32 in the checkpoint but \(64,\) float32",
        ),
        (make_state(0, tx=optax.sgd(1e-3)), r"checkpoint leaf 'opt_state\.0\.count' is not in like_state"),
        (
            make_state(0).replace(params={**make_state(0).params, "extra": jnp.zeros(3)}),
            r"leaf 'params\.extra' of like_state is not in the checkpoint",
        ),
    ],
    ids=["shape", "dtype", "missing-leaf", "extra-leaf"],
)
def test_layout_mismatch_names_leaf(tmp_path, like, pattern):
    ck.save(tmp_path, 1, make_state(1), META)
    with pytest.raises(ck.CheckpointError, match=pattern) as info:
        ck.restore(tmp_path, like)
    assert "\n" not in str(info.value)


def test_meta_mismatch_names_key(tmp_path):
    ck.save(tmp_path, 1, make_state(1), META)
    with pytest.raises(ck.CheckpointError, match=r"saved with lr=0\.0003 but lr=0\.001 is expected"):
        ck.restore(tmp_path, make_state(0), expect_meta={**META, "lr": 1e-3})
    with pytest.raises(ck.CheckpointError, match=r"net\.width=256 but net\.width=512"):
        ck.restore(tmp_path, make_state(0), expect_meta={**META, "net": {"width": 512, "depth": 2}})
    with pytest.raises(ck.CheckpointError, match=r"extra=<absent> but extra=1"):
        ck.restore(tmp_path, make_state(0), expect_meta={**META, "extra": 1})
    # keys the caller does not ask about (progress, timings) are not compared
    ck.restore(tmp_path, make_state(0), expect_meta={k: v for k, v in META.items() if k != "seed"})
    # the same check reads the meta alone, so a resume is refused before anything compiles
    saved = ck.saved_meta(tmp_path, 1)
    with pytest.raises(ck.CheckpointError, match=r"saved with lr=0\.0003 but lr=0\.001 is expected"):
        ck.check_meta(tmp_path, 1, {**META, "lr": 1e-3}, saved)
    ck.check_meta(tmp_path, 1, META, saved)


def _largest_data_file(step_dir: Path) -> Path:
    """The biggest array-data file (tensorstore keeps them in ``d/`` folders), i.e. the replay buffer."""
    files = [p for p in (step_dir / "state").rglob("*") if p.is_file() and p.parent.name == "d"]
    return max(files, key=lambda p: p.stat().st_size)


def _truncate(path: Path):
    data = path.read_bytes()
    path.write_bytes(data[: len(data) // 2])


def _flip_byte(path: Path):
    data = bytearray(path.read_bytes())
    data[len(data) // 2] ^= 0x10  # decodes without error in orbax; only the CRC catches it
    path.write_bytes(bytes(data))


def _garbage(path: Path):
    path.write_bytes(np.random.default_rng(0).bytes(path.stat().st_size))


@pytest.mark.parametrize(
    "target, damage, reason",
    [
        (_largest_data_file, _truncate, ""),
        (_largest_data_file, _flip_byte, r"leaf 'buffer\.obs' fails its CRC32 check"),
        (lambda d: d / "state" / "_METADATA", _garbage, ""),
        (lambda d: d / "meta" / "metadata", _truncate, ""),
    ],
    ids=["truncated-data", "flipped-byte", "garbage-metadata", "truncated-meta"],
)
def test_corrupt_checkpoint(tmp_path, target, damage, reason):
    ck.save(tmp_path, 1, make_state(1), META)
    ck.save(tmp_path, 2, make_state(2), META)
    damage(target(ck.checkpoint_dir(tmp_path) / "2"))
    pattern = rf"checkpoints/2 is corrupt or unreadable \(.*{reason}.*\); other steps: \[1\]$"
    with pytest.raises(ck.CheckpointError, match=pattern) as info:
        ck.restore(tmp_path, make_state(0))
    assert "\n" not in str(info.value)
    assert_bitwise_equal(ck.restore(tmp_path, make_state(0), step=1)[1], make_state(1))


KILLED_SAVE = textwrap.dedent(
    """
    import os, signal, sys
    import numpy as np
    from splid_jax.runtime import checkpoint as ck

    run_dir = sys.argv[1]
    ck.save(run_dir, 1, {"w": np.arange(100_000, dtype=np.float32)}, {"k": 1})
    real_rename = os.rename

    def rename(src, dst, *a, **k):  # die at the commit point, with the step fully written
        if ".orbax-checkpoint-tmp" in str(src):
            os.kill(os.getpid(), signal.SIGKILL)
        return real_rename(src, dst, *a, **k)

    os.rename = rename
    ck.save(run_dir, 2, {"w": np.ones(100_000, dtype=np.float32)}, {"k": 1})
    """
)


def test_killed_mid_save_leaves_previous_step(tmp_path):
    env = {**os.environ, "PYTHONPATH": f"{REPO}{os.pathsep}{os.environ.get('PYTHONPATH', '')}", "JAX_PLATFORMS": "cpu"}
    proc = subprocess.run(
        [sys.executable, "-c", KILLED_SAVE, str(tmp_path)], env=env, capture_output=True, text=True, timeout=120
    )
    assert proc.returncode == -signal.SIGKILL, proc.stderr[-2000:]
    leftovers = [p.name for p in ck.checkpoint_dir(tmp_path).iterdir() if "tmp" in p.name]
    assert leftovers and all(name.startswith("2.") for name in leftovers)

    like = {"w": np.zeros(100_000, np.float32)}
    assert ck.latest_step(tmp_path) == 1
    step, state, meta = ck.restore(tmp_path, like, expect_meta={"k": 1})
    assert step == 1 and np.array_equal(state["w"], np.arange(100_000, dtype=np.float32))

    assert ck.save(tmp_path, 2, {"w": np.ones(100_000, dtype=np.float32)}, {"k": 1})
    assert sorted(p.name for p in ck.checkpoint_dir(tmp_path).iterdir()) == ["1", "2"]
    assert np.array_equal(ck.restore(tmp_path, like)[1]["w"], np.ones(100_000, np.float32))


@pytest.mark.parametrize(
    "error, found",
    [
        (OSError(28, "No space left on device"), (28, "No space left on device")),
        (OSError(30, "Read-only file system", "/r/checkpoints"), (30, "Read-only file system: /r/checkpoints")),
        (ValueError("PERMISSION_DENIED: Failed writing: x [os_error_code='13']"), (13, os.strerror(13))),
        (ValueError("RESOURCE_EXHAUSTED: Failed to write 427 bytes: No space left on device"), (28, os.strerror(28))),
        (FileNotFoundError(2, "No such file or directory"), None),
        (ValueError("shape mismatch"), None),
    ],
)
def test_a_refused_write_is_told_from_other_errors_through_orbaxs_wrapping(error, found):
    wrapped = RuntimeError("orbax failed")
    wrapped.__cause__ = error
    assert ck.write_failure(error) == found and ck.write_failure(wrapped) == found
    assert ck.is_no_space(wrapped) == (found is not None and found[0] == 28)


def test_orbax_thread_tracebacks_and_closed_loop_callbacks_are_not_printed():
    import logging

    try:
        raise ValueError("RESOURCE_EXHAUSTED")
    except ValueError:
        record = logging.LogRecord("absl", logging.ERROR, "/x/orbax/checkpoint/future.py", 1, "raised", (),
                                   sys.exc_info())  # fmt: skip
    absl = logging.getLogger("absl")
    assert not all(f.filter(record) for f in absl.filters)
    record.pathname = "/x/elsewhere.py"
    assert all(f.filter(record) for f in absl.filters)
    seen = []  # pytest replaces sys.unraisablehook while a test runs: the wrapper, wrapped around a list
    hook = ck.quiet_closed_loops(seen.append)
    for text in ("Event loop is closed", "another"):
        hook(type("U", (), {"exc_value": RuntimeError(text)})())
    assert [str(u.exc_value) for u in seen] == ["another"]


def test_a_checkpoint_rotated_out_while_read_gives_the_then_newest(tmp_path, monkeypatch):
    import shutil

    import orbax.checkpoint as ocp

    for step in (1, 2, 3):
        ck.save(tmp_path, step, make_state(step, obs_shape=(4, 5)), META)
    real, removed = ocp.CheckpointManager.restore, []

    def rotating(self, step, *a, **kw):  # the run writing them saves 4 and drops 1..3 meanwhile
        if not removed:
            removed.append(step)
            shutil.rmtree(tmp_path / "checkpoints" / str(step))
        return real(self, step, *a, **kw)

    monkeypatch.setattr(ocp.CheckpointManager, "restore", rotating)
    step, state, _ = ck.restore(tmp_path, make_state(0, obs_shape=(4, 5)))
    assert removed == [3] and step == 2
    np.testing.assert_array_equal(state.buffer.obs, make_state(2, obs_shape=(4, 5)).buffer.obs)
    removed.clear()
    with pytest.raises(ck.Rotated, match="removed while it was read"):  # a step asked for is not replaced
        ck.restore(tmp_path, make_state(0, obs_shape=(4, 5)), step=2)
