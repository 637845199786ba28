"""The fingers on Push's cube top face, in both simulators' traces of ``python -m splid_jax.evaluate ... --traces``.

    python on_top.py TRACES.npz...

Per simulator: the share of steps on the top (the grip site 3 to 5.5 cm above the cube's centre and within 5 cm of it
across; resting there it is 4.3 cm above), the episodes that end there among the final-step failures and the
never-reached ones, and per step on the top how often the next one is off it, with the stays' median length.
"""

import sys

import numpy as np


def grip_on_top(grip: np.ndarray, cube: np.ndarray) -> np.ndarray:
    """Whether the grip site [..., 3] rests on the cube's [..., 3] top face, over any leading axes."""
    dz = grip[..., 2] - cube[..., 2]
    across = np.linalg.norm(grip[..., 0:2] - cube[..., 0:2], axis=-1)
    return (dz > 0.03) & (dz < 0.055) & (across < 0.05)


def on_top(obs: np.ndarray) -> np.ndarray:
    """[episodes, steps] bool from observations [episodes, steps, 25] (grip 0:3, cube 3:6)."""
    return grip_on_top(obs[..., 0:3], obs[..., 3:6])


def stays(on: np.ndarray) -> list[int]:
    runs = []
    for row in on:
        n = 0
        for v in list(row) + [False]:
            if v:
                n += 1
            elif n:
                runs.append(n)
                n = 0
    return runs


def main(paths: list[str]) -> None:
    for path in paths:
        t = np.load(path)
        for sim in ("ours", "fetch"):
            on, success = on_top(t[f"{sim}_obs"]), t[f"{sim}_success"]
            fail, never, end = ~success[:, -1], ~success.any(1), on[:, -1]
            leave = (on[:, :-1] & ~on[:, 1:]).sum() / max(on[:, :-1].sum(), 1)
            runs = stays(on)
            print(f"{path.split('/')[-1]} {sim}: steps on top {on[:, 1:].mean():.3f}; ending on top: {end.sum()} "
                  f"(final-step failures {(end & fail).sum()} of {fail.sum()}; never reached {(end & never).sum()} "
                  f"of {never.sum()}); off the top the next step {leave:.3f} of the steps on it, median stay "
                  f"{np.median(runs) if runs else 0:.0f} steps, {len(runs)} stays")


if __name__ == "__main__":
    main(sys.argv[1:])
