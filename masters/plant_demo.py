"""Runs the TowingPlant FMU alone under fmpy with constant inputs and draws the tow's track.

The forward tug (tug2) tows with 1 N on its towline (ideal winch) and 2.12 N of surge thrust:
at 1 N of tension CyberShip II settles at 0.426 m/s (Skjetne et al. 2004), where the tug's
own drag (d11 = 2.64 N s/m, damping set A) takes the other 1.12 N, so the tow settles into a
steady run. The aft tug (tug1) is idle with its line slack: a slack line transmits no force,
so it stays behind. Nothing steers. The TitoNeri's sway-yaw motion is open-loop unstable at
this speed (../shared/reference/vessels.md), so the unsteered forward tug eventually yaws
off the line: the reason the controller needs a tug loop that stabilises it.

Writes OUT/track.csv (every output, one row per 0.1 s) and OUT/track.png (map: East
horizontal, North vertical, equal aspect).
"""

import argparse
import math
import pathlib

import fmpy
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from fmpy.util import write_csv  # noqa: E402

INPUTS = {
    "tug2.force_surge": 2.12,
    "towline2.tension_cmd": 1.0,
    "tug1.force_surge": 0.0,
    "towline1.tension_cmd": 0.0,
}

VESSELS = {"ship": (1.255, 0.29, "tab:red"), "tug1": (0.97, 0.30, "tab:green"), "tug2": (0.97, 0.30, "tab:blue")}


def hull(x, y, psi, length, width):
    """Outline of a hull (pointed bow) in (East, North) coordinates."""
    pts = [(length / 2, 0), (length / 4, width / 2), (-length / 2, width / 2), (-length / 2, -width / 2), (length / 4, -width / 2)]
    c, s = math.cos(psi), math.sin(psi)
    north = [x + px * c - py * s for px, py in pts]
    east = [y + px * s + py * c for px, py in pts]
    return east + east[:1], north + north[:1]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--fmu", required=True, help="path of TowingPlant.fmu")
    parser.add_argument("--out", required=True, help="output directory")
    parser.add_argument("--stop-time", type=float, default=100.0, help="simulated seconds (default 100)")
    args = parser.parse_args()

    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    md = fmpy.read_model_description(args.fmu)
    outputs = [v.name for v in md.modelVariables if v.causality == "output"]
    result = fmpy.simulate_fmu(
        args.fmu,
        stop_time=args.stop_time,
        output_interval=0.1,
        start_values=INPUTS,
        output=outputs,
    )
    write_csv(str(out / "track.csv"), result)

    fig, ax = plt.subplots(figsize=(9, 9))
    for name, (length, width, color) in VESSELS.items():
        ax.plot(result[f"{name}.y"], result[f"{name}.x"], color=color, lw=1, label=name)
        for i in range(0, len(result), max(1, len(result) // 6)):
            e, n = hull(result[f"{name}.x"][i], result[f"{name}.y"][i], result[f"{name}.psi"][i], length, width)
            ax.fill(e, n, color=color, alpha=0.6)
    for k in range(1, 9):
        kind = result[f"obstacle[{k}].kind"]
        if kind.max() == 0:
            continue
        active = kind > 0
        if kind[active][0] == 1:
            r = result[f"obstacle[{k}].length"][0] / 2
            ax.add_patch(plt.Circle((result[f"obstacle[{k}].y"][0], result[f"obstacle[{k}].x"][0]), r, color="grey"))
        else:
            ax.plot(result[f"obstacle[{k}].y"][active], result[f"obstacle[{k}].x"][active], "k--", lw=0.8)
    ax.set_aspect("equal")
    ax.set_xlabel("East y (m)")
    ax.set_ylabel("North x (m)")
    ax.set_title(f"TowingPlant under fmpy: forward tug towing, aft tug idle, {args.stop_time:g} s")
    ax.grid(True, lw=0.3)
    ax.legend()
    fig.savefig(out / "track.png", dpi=120, bbox_inches="tight")
    print(f"wrote {out / 'track.csv'} and {out / 'track.png'}")


if __name__ == "__main__":
    main()
