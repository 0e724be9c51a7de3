#!/usr/bin/env python3
"""Times `World.step(N)` of the Python bindings on a scene file and prints
the time per step and a hash of the final positions (the same bits
whatever the binding's loop does).

    python3 bench/scenes/py_steps.py cloth128.toml 5000
"""

import hashlib
import sys
import time

import animats


def main() -> None:
    path, n = sys.argv[1], int(sys.argv[2])
    world = animats.load(path).world()
    start = time.perf_counter()
    world.step(n)
    took = time.perf_counter() - start
    digest = hashlib.sha256(world.positions().tobytes()).hexdigest()[:16]
    print(f"{n} steps: {took * 1e3:.1f} ms = {took / n * 1e6:.1f} us/step; positions {digest}")


if __name__ == "__main__":
    main()
