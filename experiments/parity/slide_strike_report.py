"""Slide's strike: the figures, tables and plot that ``slide_strike.py`` prints and draws from its runs' records."""

from __future__ import annotations

import numpy as np


def stats(result: dict) -> dict:
    """Summary figures of one side's run."""
    eps = result["episodes"]
    f = lambda k: np.array([e[k] for e in eps], float)  # noqa: E731
    want, vg, vp, along = f("want"), f("v_grip"), f("v_puck"), f("along")
    struck = np.isfinite(vg) & (vg > 0.05)
    return {
        "episodes": len(eps),
        "any": 100 * f("success_any").mean(),
        "final": 100 * f("success_final").mean(),
        "grip_over_want": (np.mean(vg[struck] / want[struck]), np.std(vg[struck] / want[struck])),
        "launch_over_grip": (np.mean(vp[struck] / vg[struck]), np.std(vp[struck] / vg[struck])),
        "launch_over_want": (np.mean(vp / want), np.std(vp / want)),
        "along": (np.median(along), *np.percentile(along, [5, 95])),
        "long": 100 * np.mean(along > 0.05),
        "short": 100 * np.mean(along < -0.05),
        "strikes": np.mean(f("strikes")),
    }


def response_rms(ours: dict, reference: dict) -> float:
    """RMS difference (m/s) of the free-space responses, over the 120 ms after the target jump."""
    a, b = np.asarray(ours["response_speed"]), np.asarray(reference["response_speed"])
    n = min(len(a), len(b))
    return float(np.sqrt(np.mean((a[:n] - b[:n]) ** 2)))


def _pm(mean_std) -> str:
    return "{:.3f} ± {:.3f}".format(*mean_std)


def summary(results: list[dict]) -> str:
    rows = [("episodes", lambda s: f"{s['episodes']}"),
            ("success any / final (%)", lambda s: f"{s['any']:.1f} / {s['final']:.1f}"),
            ("grip speed at first contact / wanted launch", lambda s: _pm(s["grip_over_want"])),
            ("peak puck speed / grip speed at contact", lambda s: _pm(s["launch_over_grip"])),
            ("peak puck speed / wanted launch", lambda s: _pm(s["launch_over_want"])),
            ("end along the line, m: median [p5, p95]", lambda s: "{:+.3f} [{:+.3f}, {:+.3f}]".format(*s["along"])),
            ("ended > 5 cm past / short of the goal (%)", lambda s: f"{s['long']:.1f} / {s['short']:.1f}"),
            ("finger-puck contacts begun per episode", lambda s: f"{s['strikes']:.2f}")]
    ss = [stats(r) for r in results]
    out = ["| | " + " | ".join(r["side"] for r in results) + " |", "|---|" + "---:|" * len(results)]
    out += [f"| {name} | " + " | ".join(fmt(s) for s in ss) + " |" for name, fmt in rows]
    out += ["", "Free-space grip speed (m/s) after the target jump, every 4 ms:", "",
            "| ms | " + " | ".join(r["side"] for r in results) + " |", "|---:|" + "---:|" * len(results)]
    for k, ms in enumerate(results[0]["response_ms"][:12]):
        out.append(f"| {ms} | " + " | ".join(f"{r['response_speed'][k]:.3f}" for r in results) + " |")
    return "\n".join(out)


def plot(results: list[dict], grid: dict | None, path: str) -> None:
    """Left: success against the mean launch speed (grid of ours, and each side's run); right: where
    the pucks end along the line."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4.6))
    if grid:
        x = [r["launch_over_want"] for r in grid["runs"]]
        a.scatter(x, [r["any"] for r in grid["runs"]], marker="^", color="0.6", label="ours, other drives: any step")
        a.scatter(x, [r["final"] for r in grid["runs"]], marker="v", color="0.3",
                  label="ours, other drives: final step")
    for r, colour in zip(results, ("tab:red", "tab:blue", "tab:green"), strict=False):
        s = stats(r)
        a.scatter([s["launch_over_want"][0]] * 2, [s["any"], s["final"]], s=90, marker="*", color=colour,
                  label=f"{r['side']} (any, final)")
        along = np.array([e["along"] for e in r["episodes"]])
        b.hist(np.clip(along, -0.15, 0.15), bins=np.linspace(-0.15, 0.15, 61), histtype="step", color=colour,
               label=r["side"])
    a.set_xlabel("mean peak puck speed / wanted launch speed")
    a.set_ylabel("scripted Slide success (%)")
    a.grid(alpha=0.3)
    b.axvspan(-0.05, 0.05, color="0.9", label="within 5 cm along the line")
    b.set_xlabel("where the puck ends along the start-goal line, m\n"
                 "(> 0: past the goal; beyond +-0.15 drawn at +-0.15)")
    b.set_ylabel("episodes")
    for ax in (a, b):
        ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.18 if ax is a else -0.26), ncol=2, fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
