#!/usr/bin/env python3
"""Writes a scene file of a square cloth: SIDE x SIDE beads of 1 g, 1 m
across, joined to their grid neighbours by springs (k = 100 N/m), hanging
from its two top corners, symplectic Euler at 0.1 ms.

    python3 bench/scenes/cloth.py 128 > cloth128.toml
    animats simulate cloth128.toml --duration 1

With `--on-floor`, the cloth instead lies free as a low dome (1 to 3 cm
up) over the engine's floor, and falls onto it: a large world with the
floor's collisions and contact force.

    python3 bench/scenes/cloth.py 128 --on-floor > floor128.toml

A scene-file twin of the cloth-128 workload, for timing the CLI's and the
Python bindings' own loops (docs/PERFORMANCE.md).
"""

import math
import sys


def main() -> None:
    args = [a for a in sys.argv[1:] if a != "--on-floor"]
    on_floor = len(args) < len(sys.argv) - 1
    try:
        side = int(args[0]) if args else 128
    except ValueError:
        sys.exit(f"cloth.py: the side must be a whole number, got {args[0]!r}")
    if not 2 <= side <= 1000:
        # A scene file holds at most 1,000,000 particles (1000 x 1000).
        sys.exit(f"cloth.py: the side must be 2 to 1000, got {side}")
    h = 1.0 / (side - 1)
    out = [
        "[world]",
        "gravity = [0.0, -9.8, 0.0]",
        "dt = 0.0001",
        'integrator = "symplectic"',
        "duration = 0.1",
        "",
    ]
    if on_floor:
        out += ["[floor]", ""]
    for i in range(side):
        for j in range(side):
            fixed = j == side - 1 and i in (0, side - 1) and not on_floor
            if on_floor:
                y = 0.01 + 0.02 * math.sin(math.pi * i * h) * math.sin(math.pi * j * h)
                at = f"[{i * h:.6f}, {y:.6f}, {j * h:.6f}]"
            else:
                at = f"[{i * h:.6f}, {1.0 + j * h:.6f}, 0.0]"
            out += [
                "[[particle]]",
                f'name = "p{i}_{j}"',
                "mass = 0.001",
                "radius = 0.002",
                f"position = {at}",
            ]
            out += ["fixed = true"] if fixed else []
            out.append("")

    def spring(a: str, b: str) -> None:
        out.extend(["[[spring]]", f'a = "{a}"', f'b = "{b}"', "stiffness = 100.0", "damping = 0.01", ""])

    for i in range(side):
        for j in range(side):
            if i + 1 < side:
                spring(f"p{i}_{j}", f"p{i + 1}_{j}")
            if j + 1 < side:
                spring(f"p{i}_{j}", f"p{i}_{j + 1}")
    sys.stdout.write("\n".join(out))


if __name__ == "__main__":
    main()
