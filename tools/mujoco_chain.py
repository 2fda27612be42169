"""The benchmark's spatial chain in MuJoCo, timed against cdyn's in one run.

The chain of `cdyn::spatial::chain`: N rods of 1 kg, 1 m and radius 1 cm,
released at rest 0.3 rad from the vertical under g = 1, step 1e-3, one
evaluation per step (MuJoCo's semi-implicit Euler; cdyn's AB-3). In MuJoCo
it is built two ways:

- `connect`: free bodies joined by `connect` equality constraints, the
  redundant-coordinate model cdyn uses; MuJoCo keeps them softly, so the
  joints open (the largest gap over the first second is reported; cdyn's
  largest |Φ| is in `cdyn bench`);
- `ball`: bodies nested by ball joints (minimal coordinates, exact joints);
  its mass matrix is dense for a chain, so only small N are timed.

cdyn's step is timed by its profiling example (`spatial_chain_step`), run
between MuJoCo's trials so that both see the same machine. Usage:
`tools/mujoco-compare.sh` (it installs MuJoCo in a virtual environment).
"""

import math
import re
import subprocess
import sys
import time

import mujoco
import numpy as np

H, G, THETA0 = 1e-3, 1.0, 0.3
D = (math.sin(THETA0), 0.0, -math.cos(THETA0))
OPTION = (f'<option timestep="{H}" gravity="0 0 {-G}" integrator="Euler">'
          '<flag contact="disable"/></option>')


def connect(n):
    bodies, joints = [], []
    half = f"{D[0] / 2} 0 {D[2] / 2}"
    minus = f"{-D[0] / 2} 0 {-D[2] / 2}"
    for i in range(n):
        c = [x * (i + 0.5) for x in D]
        bodies.append(f'<body name="b{i}" pos="{c[0]} 0 {c[2]}"><freejoint/>'
                      f'<geom type="capsule" fromto="{minus} {half}" size="0.01" mass="1"/></body>')
        other = f' body2="b{i - 1}"' if i else ""
        joints.append(f'<connect body1="b{i}"{other} anchor="{minus}"/>')
    return (f'<mujoco>{OPTION}<worldbody>{"".join(bodies)}</worldbody>'
            f'<equality>{"".join(joints)}</equality></mujoco>')


def ball(n):
    body = ''.join(f'<body pos="{"0 0 0" if i == 0 else f"{D[0]} 0 {D[2]}"}"><joint type="ball"/>'
                   f'<geom type="capsule" fromto="0 0 0 {D[0]} 0 {D[2]}" size="0.01" mass="1"/>'
                   for i in range(n))
    return f'<mujoco>{OPTION}<worldbody>{body}{"</body>" * n}</worldbody></mujoco>'


def mujoco_step(xml, steps, gap_until=0.0):
    """Microseconds per step over the first `steps` steps; with `gap_until`,
    the largest gap of a `connect` joint until that time, sampled every 10
    steps (outside the clock)."""
    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)
    elapsed, gap, taken = 0.0, 0.0, 0
    while taken < steps or data.time < gap_until - H / 2:
        start = time.perf_counter()
        for _ in range(10):
            mujoco.mj_step(model, data)
        if taken < steps:
            elapsed += time.perf_counter() - start
        taken += 10
        rows = data.efc_type[:data.nefc] == mujoco.mjtConstraint.mjCNSTR_EQUALITY
        if rows.any():
            gap = max(gap, float(np.abs(data.efc_pos[:data.nefc][rows]).max()))
    return elapsed / steps * 1e6, gap


def cdyn_step(example, n, steps):
    out = subprocess.run([example, str(n), str(steps), "cdyn"], check=True, capture_output=True, text=True).stdout
    return float(re.search(r"([0-9.]+) µs per step", out).group(1))


def main():
    example, trials = sys.argv[1], 3
    print(f"MuJoCo {mujoco.__version__}; best of {trials} interleaved trials; µs per step")
    print(f"{'N':>6} {'steps':>6} {'cdyn':>10} {'connect':>10} {'gap, 1 s':>10} {'ball':>10}"
          f" {'connect/cdyn':>13}")
    for n, steps in ((10, 2000), (100, 500), (1000, 100)):
        cdyn, conn, gap, nested = math.inf, math.inf, 0.0, math.inf
        for _ in range(trials):
            cdyn = min(cdyn, cdyn_step(example, n, steps))
            us, g = mujoco_step(connect(n), steps, gap_until=0.0 if gap else 1.0)
            conn, gap = min(conn, us), max(gap, g)
            if n <= 100:
                nested = min(nested, mujoco_step(ball(n), max(20, steps // n))[0])
        nested_text = f"{nested:10.1f}" if nested < math.inf else f"{'-':>10}"
        print(f"{n:>6} {steps:>6} {cdyn:10.1f} {conn:10.1f} {gap:10.2e} {nested_text} {conn / cdyn:12.2f}×",
              flush=True)


if __name__ == "__main__":
    main()
