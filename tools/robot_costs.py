"""cdyn's step on real robots against Pinocchio's ABA and MuJoCo's step.

For each robot of example-robot-data, in one run (so that all three see
the same machine), microseconds per call:

- cdyn (`examples/robot_step.rs`): a step of AB-3 without control (one
  evaluation of the dynamics in redundant coordinates: M(q) by blocks,
  Φ_q and γ by automatic differentiation, S factored), of AB-3 with
  `robust`, of RK-4 (four evaluations) and of generalized-α (implicit),
  h = 1e-4, best of 5 trials; the same in joint coordinates
  (`Mechanism::in_joint_coordinates`: one coordinate per joint, M(θ) and
  the velocity terms by the composite-body and Newton-Euler passes);
- Pinocchio: `pin.aba` (forward dynamics in joint coordinates) called from
  Python, best of 5 trials of 20 000 calls, less the same call on a model
  of one revolute joint (the per-call floor of Python and the bindings,
  0.3-0.5 µs here), which leaves the C++ ABA's own cost;
- MuJoCo: `mj_step` with its Euler, RK4 and implicitfast integrators, looped in C
  (`nstep`), on the URDF with its visual and collision elements removed
  (MuJoCo cannot read the package's meshes) and contacts off.

Usage: `tools/robot-costs.sh` (installs the packages in a virtual environment).
"""

import importlib.metadata
import json
import os
import re
import subprocess
import sys
import tempfile
import time

import mujoco
import numpy as np
import pinocchio as pin

ROBOTS = [
    ("UR5", "ur_description/urdf/ur5_robot.urdf"),
    ("Kinova", "kinova_description/robots/kinova.urdf"),
    ("Z1", "z1_description/urdf/z1.urdf"),
    ("xArm7", "xarm_description/urdf/xarm7.urdf"),
    ("SO-100", "so_arm_description/urdf/so100.urdf"),
    ("Panda", "panda_description/urdf/panda.urdf"),
]


def robots_dir():
    # As python/tests/test_robots.py finds them: the package installs its files, not a module.
    return str(importlib.metadata.distribution("example-robot-data").locate_file(
        "cmeel.prefix/share/example-robot-data/robots"))


def best_per_call(call, calls=20_000, trials=5):
    best = float("inf")
    for _ in range(trials):
        start = time.perf_counter()
        for _ in range(calls):
            call()
        best = min(best, (time.perf_counter() - start) / calls)
    return best * 1e6


def aba_call(model):
    data = model.createData()
    q, v, tau = pin.neutral(model), np.zeros(model.nv), np.zeros(model.nv)
    return lambda: pin.aba(model, data, q, v, tau)


def floor_model():
    model = pin.Model()
    joint = model.addJoint(0, pin.JointModelRZ(), pin.SE3.Identity(), "j")
    model.appendBodyToJoint(joint, pin.Inertia(1.0, np.zeros(3), np.eye(3)), pin.SE3.Identity())
    return model


def mujoco_model(path):
    text = open(path).read()
    text = re.sub(r"<visual>.*?</visual>|<collision>.*?</collision>", "", text, flags=re.S)
    text = re.sub(r"(<robot[^>]*>)", r'\1<mujoco><compiler discardvisual="true" fusestatic="false"/></mujoco>',
                  text, count=1)
    with tempfile.NamedTemporaryFile("w", suffix=".urdf", delete=False) as f:
        f.write(text)
    try:
        model = mujoco.MjModel.from_xml_path(f.name)
    finally:
        os.unlink(f.name)
    model.opt.timestep = 1e-4
    model.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONTACT
    return model


def mujoco_step(model, integrator, steps=20_000, trials=5):
    model.opt.integrator = integrator
    best = float("inf")
    for _ in range(trials):
        data = mujoco.MjData(model)
        start = time.perf_counter()
        mujoco.mj_step(model, data, nstep=steps)
        best = min(best, (time.perf_counter() - start) / steps)
    return best * 1e6


def main():
    binary = sys.argv[1]
    root = robots_dir()
    floor = best_per_call(aba_call(floor_model()))
    print(f"Pinocchio per-call floor (ABA of one revolute joint from Python): {floor:.3f} µs")
    rows = []
    for name, relative in ROBOTS:
        path = os.path.join(root, relative)
        out = subprocess.run([binary, path], check=True, capture_output=True, text=True).stdout
        cdyn = json.loads(out)
        aba = best_per_call(aba_call(pin.buildModelFromUrdf(path))) - floor
        mj = mujoco_model(path)
        euler = mujoco_step(mj, mujoco.mjtIntegrator.mjINT_EULER)
        rk4 = mujoco_step(mj, mujoco.mjtIntegrator.mjINT_RK4)
        implicit = mujoco_step(mj, mujoco.mjtIntegrator.mjINT_IMPLICITFAST)
        rows.append((name, cdyn, aba, euler, rk4, implicit))
    print("\nBody coordinates:\n")
    print("| Robot | n, m | cdyn AB-3 | cdyn AB-3, robust | cdyn RK-4 | cdyn generalized-α | Pinocchio ABA (C++) "
          "| MuJoCo Euler | MuJoCo RK4 | MuJoCo implicitfast |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for name, cdyn, aba, euler, rk4, implicit in rows:
        print(f"| {name} | {cdyn['n']}, {cdyn['m']} | {cdyn['ab3_us']:.2f} | {cdyn['ab3_robust_us']:.2f} "
              f"| {cdyn['rk4_us']:.2f} | {cdyn['alpha_us']:.2f} | {aba:.2f} | {euler:.2f} | {rk4:.2f} "
              f"| {implicit:.2f} |")
    print("\nJoint coordinates:\n")
    print("| Robot | n, m | cdyn AB-3 | cdyn AB-3, robust | cdyn RK-4 | cdyn generalized-α | Pinocchio ABA (C++) "
          "| AB-3 / ABA |")
    print("|---|---|---|---|---|---|---|---|")
    for name, cdyn, aba, *_ in rows:
        print(f"| {name} | {cdyn['joints_n']}, {cdyn['joints_m']} | {cdyn['joints_ab3_us']:.2f} "
              f"| {cdyn['joints_ab3_robust_us']:.2f} | {cdyn['joints_rk4_us']:.2f} | {cdyn['joints_alpha_us']:.2f} "
              f"| {aba:.2f} | {cdyn['joints_ab3_us'] / aba:.2f} |")


if __name__ == "__main__":
    main()
