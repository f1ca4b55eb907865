#!/usr/bin/env python3
"""The settled packing of `talus bench` (packing-N) as a scene file, its particles listed
in row order or shuffled (ids in no order in space, as a pour leaves them), for timing
the CPU path's memory order with `talus run` (issue 13).

    benches/peers/packing_scene.py N [shuffled] [STEPS] > scene.json
    talus run scene.json --backend cpu --threads 1 --out /tmp/x   # prints particle-steps/s
"""
import json
import math
import random
import sys

n = int(sys.argv[1])
shuffled = len(sys.argv) > 2 and sys.argv[2] == "shuffled"
steps = int(sys.argv[3]) if len(sys.argv) > 3 else 600
cols = max(2, math.ceil(math.sqrt(2 * n)))
h = math.sqrt(3) / 2
particles = []
for k in range(n):
    c, r = k % cols, k // cols
    x = c + (0.5 if r % 2 == 1 else 0.0) + 0.5
    particles.append({"position": [x, 0.5 + r * h], "diameter": 1.0})
if shuffled:
    random.seed(1)
    random.shuffle(particles)
w = cols + 1.0
top = (n // cols + 2) * h + 2.0
dt = 0.002
scene = {
    "name": f"packing-{n}" + ("-shuffled" if shuffled else ""),
    "dt": dt,
    "stop": {"time": steps * dt},
    "gravity": {"g": [0.0, -1.0]},
    "domain": {"x": [-2.0, w + 2.0], "z": [-2.0, top]},
    "materials": {"m": {"density": 1.2732395447351628}},
    "contact": {"law": "spring_dashpot", "k_n": 2000.0, "gamma_n": 10.0, "k_t": 571.4,
                "gamma_t": 2.0, "mu": 0.5},
    "walls": [{"from": [0.0, 0.0], "to": [w, 0.0]}, {"from": [0.0, 0.0], "to": [0.0, top]},
              {"from": [w, 0.0], "to": [w, top]}],
    "particles": [{"kind": "list", "material": "m", "particles": particles}],
    # Log every 250 steps: the run advances in stretches of 250 steps.
    "output": {"checkpoint_every": 0, "log_every": 250 * dt},
}
print(json.dumps(scene))
