"""Whether MuJoCo C's choice of FetchSlide-v4's four puck-table points (``rest_support.txt``) follows from its
polygon clipping and pruning (``polygonClip`` and ``polygonQuad`` in its ``engine_collision_gjk.c``, re-stated here)
applied to the puck's rim as a 16-gon: every ordering of the two polygons tried, the yaws on which each reproduces the
observed set. The table's top and the puck's place are the reference's in ``rest_support.py``.

    python experiments/results/2026-11-29/slide-10000/support_quad.py
"""

from __future__ import annotations

import itertools

import numpy as np

OBSERVED = {0: {67.5, 157.5, 247.5, 337.5}, 10: {0, 90, 157.5, 270}, 22.5: {0, 90, 157.5, 270},
            45: {67.5, 157.5, 247.5, 337.5}, 90: {22.5, 112.5, 202.5, 292.5}, 200: {22.5, 135, 225, 315}}  # fmt: skip
TABLE_CENTRE, TABLE_HALF = np.array([1.32441906, 0.75018422]), np.array([0.625, 0.45])
PUCK, RADIUS, SIDES = np.array([1.16300271, 0.84915414]), 0.025, 16


def area4(a, b, c, d):
    return 0.5 * np.linalg.norm(np.cross(d - a, b - d) + np.cross(c - b, a - c))


def largest_quad(p: np.ndarray) -> tuple[int, int, int, int]:
    """C's greedy walk for a quadrilateral of largest area among a convex polygon's vertices."""
    n = len(p)
    nxt = lambda i: (i + 1) % n  # noqa: E731
    a, b, c, d = 0, 1, 2, 3
    best, m = (a, b, c, d), area4(p[a], p[b], p[c], p[d])
    while a < n:
        while area4(p[a], p[b], p[c], p[nxt(d)]) > m:
            d = nxt(d)
            m, best = area4(p[a], p[b], p[c], p[d]), (a, b, c, d)
            while area4(p[a], p[b], p[nxt(c)], p[d]) > m:
                c = nxt(c)
                m, best = area4(p[a], p[b], p[c], p[d]), (a, b, c, d)
            while area4(p[a], p[nxt(b)], p[c], p[d]) > m:
                b = nxt(b)
                m, best = area4(p[a], p[b], p[c], p[d]), (a, b, c, d)
        if b == a:
            b = nxt(b)
            if c == b:
                c = nxt(c)
                if d == c:
                    d = nxt(d)
        a += 1
    return best


def clip(clipper: list, polygon: list, normal: np.ndarray) -> list:
    """Sutherland-Hodgman as C orders it: each edge of ``clipper`` in turn, an inside edge adds its end."""
    for i, v1 in enumerate(clipper):
        v2 = clipper[(i + 1) % len(clipper)]
        out_normal = np.cross(v2 - v1, normal)
        out_normal /= np.linalg.norm(out_normal)
        out = []
        for j, p in enumerate(polygon):
            q = polygon[(j + 1) % len(polygon)]
            inside_p, inside_q = (p - v1) @ out_normal > -1e-15, (q - v1) @ out_normal > -1e-15
            if inside_p and inside_q:
                out.append(q)
            elif inside_p or inside_q:
                t = (out_normal @ v1 - out_normal @ p) / (out_normal @ (q - p))
                if 0 <= t <= 1:
                    out.append(p + t * (q - p))
                if inside_q:
                    out.append(q)
        polygon = out
    return polygon


def chosen(yaw: float, rim_first: bool, rim_turn: int, table_turn: int, table_start: int, up: int,
           jitter: float = 0.0, rng=None) -> set:
    """The four rim angles (degrees, the puck's frame) C's clipping and pruning keep; ``jitter``: the rim's vertices
    moved by that much (m), at random, as rounding would."""
    th = np.radians(yaw)
    to_puck = np.array([[np.cos(th), np.sin(th)], [-np.sin(th), np.cos(th)]])
    rim = [np.array([RADIUS * np.cos(np.radians(rim_turn * k * 360 / SIDES)),
                     RADIUS * np.sin(np.radians(rim_turn * k * 360 / SIDES)), 0.0]) for k in range(SIDES)]  # fmt: skip
    if jitter:
        rim = [v + np.append(rng.normal(0.0, jitter, 2), 0.0) for v in rim]
    corners = [TABLE_CENTRE + TABLE_HALF * np.array(s) for s in ((1, 1), (-1, 1), (-1, -1), (1, -1))][::table_turn]
    corners = corners[table_start:] + corners[:table_start]
    table = [np.array([*(to_puck @ (c - PUCK)), 0.0]) for c in corners]
    normal = np.array([0.0, 0.0, float(up)])
    polygon = clip(rim, table, normal) if rim_first else clip(table, rim, normal)
    if len(polygon) < 5:
        return set()
    picked = (polygon[i] for i in largest_quad(np.array(polygon)))
    return {round(float(np.degrees(np.arctan2(p[1], p[0])) % 360), 1) % 360 for p in picked}


def main() -> int:
    rows = []
    for options in itertools.product((True, False), (1, -1), (1, -1), range(4), (1, -1)):
        hits = [yaw for yaw, want in OBSERVED.items() if chosen(yaw, *options) == {float(x) for x in want}]
        rows.append((len(hits), options, hits))
    rows.sort(key=lambda r: -r[0])
    for n, options, hits in rows[:3]:
        print(f"{n} of {len(OBSERVED)} yaws (rim clips the table, rim turn, table turn, "
              f"table start, normal): {options} {hits}")
    rng = np.random.default_rng(0)
    for yaw in OBSERVED:
        sets = {tuple(sorted(chosen(yaw, *rows[0][1], jitter=1e-12, rng=rng))) for _ in range(50)}
        print(f"yaw {yaw}: the best ordering's rim moved 1e-12 m at random, 50 draws: {len(sets)} sets {sorted(sets)}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
