"""Real robots against Pinocchio (the `pin` package): the URDF files of
example-robot-data, loaded by cdyn into redundant coordinates (bodies in
Euler parameters held by joint rows) and by Pinocchio into joint
coordinates, must agree on the physics.

A joint state (θ, θ̇) is carried to cdyn's coordinates through Pinocchio's
own forward kinematics: each cdyn body's frame is fixed in its link's
frame, so its pose and velocity follow from the link's. cdyn's joint
coordinates are read back by `_cdyn.urdf_joints`
(`Mechanism::joint_coordinates`). Damping and the regularized Coulomb
friction cdyn applies at a joint are given to Pinocchio as joint torques
(its dynamics ignore `<dynamics>`). Numbers measured: docs/robots.md."""

import importlib.metadata
import pathlib
import xml.etree.ElementTree as ET

import numpy as np
import pinocchio as pin
import pytest

import cdyn
from cdyn import _cdyn

ROBOTS = pathlib.Path(
    importlib.metadata.distribution("example-robot-data").locate_file("cmeel.prefix/share/example-robot-data/robots")
)
GRAVITY = [0.0, 0.0, -9.81]
SLIP = 0.01  # cdyn's FRICTION_SLIP

UR5 = "ur_description/urdf/ur5_robot.urdf"
KINOVA = "kinova_description/robots/kinova.urdf"  # continuous joints: (cos θ, sin θ) in Pinocchio
Z1 = "z1_description/urdf/z1.urdf"  # Coulomb friction and damping on every joint
XARM7 = "xarm_description/urdf/xarm7.urdf"
SO100 = "so_arm_description/urdf/so100.urdf"
PANDA = "panda_description/urdf/panda.urdf"  # a <mimic> finger: Pinocchio's mimic (reduced) model


def quaternion_product(a, b):
    """Hamilton product, scalar first."""
    return np.concatenate([[a[0] * b[0] - a[1:] @ b[1:]], a[0] * b[1:] + b[0] * a[1:] + np.cross(a[1:], b[1:])])


class Robot:
    """One URDF in both libraries."""

    def __init__(self, relative):
        self.path = ROBOTS / relative
        self.model = pin.buildModelFromUrdf(str(self.path), True)  # mimic joints as Pinocchio's mimic joints
        self.data = self.model.createData()
        self.bodies, q0, _, self.names, _, _ = _cdyn.urdf_joints(str(self.path), GRAVITY, [], [])
        self.frames = [self.model.getFrameId(b, pin.BODY) for b in self.bodies]
        # Each body's frame in its link's frame, from the zero pose (where cdyn places the robot).
        self.kinematics(pin.neutral(self.model), np.zeros(self.model.nv))
        self.offsets = []
        for i, f in enumerate(self.frames):
            r, p = q0[7 * i : 7 * i + 3], q0[7 * i + 3 : 7 * i + 7]
            body = pin.SE3(pin.Quaternion(*p).toRotationMatrix(), np.array(r))
            self.offsets.append(self.data.oMf[f].inverse() * body)
        self.dynamics = self.read_dynamics()

    def read_dynamics(self):
        """Per joint name: (damping, friction, leader, multiplier) from the URDF."""
        out = {}
        for j in ET.parse(self.path).getroot().findall("joint"):  # not a <transmission>'s
            d, m = j.find("dynamics"), j.find("mimic")
            damping = float(d.get("damping", 0)) if d is not None else 0.0
            friction = float(d.get("friction", 0)) if d is not None else 0.0
            leader = m.get("joint") if m is not None else j.get("name")
            multiplier = float(m.get("multiplier", 1)) if m is not None else 1.0
            out[j.get("name")] = (damping, friction, leader, multiplier)
        return out

    def index(self, name):
        """The name's joint velocity index in Pinocchio and its multiplier (a mimic joint follows its leader)."""
        _, _, leader, multiplier = self.dynamics[name]
        return self.model.joints[self.model.getJointId(leader)].idx_v, multiplier

    def kinematics(self, q, v):
        pin.forwardKinematics(self.model, self.data, q, v)
        pin.updateFramePlacements(self.model, self.data)

    def configuration(self, theta):
        """Pinocchio's q for joint coordinates θ (one per velocity)."""
        q = pin.neutral(self.model)
        for jm in self.model.joints[1:]:
            if jm.nq == 2:  # continuous: (cos θ, sin θ)
                q[jm.idx_q : jm.idx_q + 2] = [np.cos(theta[jm.idx_v]), np.sin(theta[jm.idx_v])]
            elif jm.nq == 1:
                q[jm.idx_q] = theta[jm.idx_v]
        return q

    def redundant(self, q, v):
        """cdyn's (q, v) at Pinocchio's (q, v): every body's centre of mass,
        Euler parameters and their rates."""
        self.kinematics(q, v)
        Q, V = [], []
        for f, offset in zip(self.frames, self.offsets):
            link = self.data.oMf[f]
            body = link * offset
            velocity = pin.getFrameVelocity(self.model, self.data, f, pin.LOCAL_WORLD_ALIGNED)
            w = velocity.angular
            r_dot = velocity.linear + np.cross(w, body.translation - link.translation)
            e = pin.Quaternion(body.rotation)
            p = np.array([e.w, e.x, e.y, e.z])
            p_dot = 0.5 * quaternion_product(np.concatenate([[0.0], w]), p)  # ṗ = ½ (0, ω) ∘ p, ω in space
            Q += [*body.translation, *p]
            V += [*r_dot, *p_dot]
        return Q, V

    def joint_torques(self, v):
        """The torques cdyn's damping and friction put on Pinocchio's coordinates."""
        tau = np.zeros(self.model.nv)
        for name in self.names:
            damping, friction, _, _ = self.dynamics[name]
            k, m = self.index(name)
            rate = m * v[k]
            tau[k] += m * (-damping * rate - friction * rate / np.sqrt(rate**2 + SLIP**2))
        return tau

    def acceleration(self, q, v):
        # M⁻¹ (τ − h) rather than ABA, which does not take Pinocchio's mimic joints.
        mass = pin.crba(self.model, self.data, q)
        mass = np.triu(mass) + np.triu(mass, 1).T
        return np.linalg.solve(mass, self.joint_torques(v) - pin.nonLinearEffects(self.model, self.data, q, v))

    def cdyn_joints(self, qs, vs):
        """cdyn's (θ, θ̇, θ̈) of every joint at each state, a dict name → array (states × 3)."""
        _, _, _, names, joints, _ = _cdyn.urdf_joints(str(self.path), GRAVITY, [list(q) for q in qs], [list(v) for v in vs])
        joints = np.array(joints)
        return {name: joints[:, i, :] for i, name in enumerate(names)}


def wrapped(x):
    return (x + np.pi) % (2 * np.pi) - np.pi


@pytest.mark.parametrize("relative", [UR5, KINOVA, Z1, XARM7, SO100, PANDA])
def test_joint_accelerations_agree_with_pinocchio_at_random_states(relative):
    robot = Robot(relative)
    rng = np.random.default_rng(31)
    states, expected = [], []
    for _ in range(4):
        theta, rate = rng.uniform(-2.0, 2.0, robot.model.nv), rng.uniform(-2.0, 2.0, robot.model.nv)
        q = robot.configuration(theta)
        states.append(robot.redundant(q, rate))
        expected.append((theta, rate, robot.acceleration(q, rate)))
    joints = robot.cdyn_joints(*zip(*states))
    assert sorted(joints) == sorted(n for n in robot.names)
    worst = np.zeros(3)
    for name, values in joints.items():
        k, m = robot.index(name)
        for (theta, rate, acc), (t, t_dot, t_ddot) in zip(expected, values):
            worst = np.maximum(worst, [abs(wrapped(t - m * theta[k])), abs(t_dot - m * rate[k]), abs(t_ddot - m * acc[k])])
    print(relative, "worst |Δθ|, |Δθ̇|, |Δθ̈|", worst)
    # The state carried over exactly, and the accelerations of Eq. 8 Pinocchio's.
    assert worst[0] < 1e-13 and worst[1] < 1e-13, worst
    assert worst[2] < 1e-9, worst


@pytest.mark.parametrize("relative", [UR5, KINOVA, Z1, XARM7, SO100, PANDA])
def test_joint_coordinates_accelerations_agree_with_pinocchio_at_random_states(relative):
    """The robot in cdyn's joint coordinates (`Mechanism::in_joint_coordinates`,
    closed-form composite-body and Newton-Euler passes), against Pinocchio
    at the same states; Panda's mimic finger is a coordinate of its own,
    held to its leader by a row."""
    robot = Robot(relative)
    names, _, _ = _cdyn.urdf_tree(str(robot.path), GRAVITY, [], [])
    assert sorted(names) == sorted(robot.names)
    rng = np.random.default_rng(32)
    thetas, rates, expected = [], [], []
    for _ in range(4):
        theta, rate = rng.uniform(-2.0, 2.0, robot.model.nv), rng.uniform(-2.0, 2.0, robot.model.nv)
        index = [robot.index(name) for name in names]
        thetas.append([m * theta[k] for k, m in index])
        rates.append([m * rate[k] for k, m in index])
        acc = robot.acceleration(robot.configuration(theta), rate)
        expected.append([m * acc[k] for k, m in index])
    _, accelerations, _ = _cdyn.urdf_tree(str(robot.path), GRAVITY, thetas, rates)
    worst = np.max(np.abs(np.array(accelerations) - np.array(expected)))
    scale = np.max(np.abs(np.array(expected)))
    print(relative, "worst |Δθ̈|", worst, "of", scale)
    assert worst < 1e-9 * max(scale, 1.0), worst


def rk4_in_joint_space(robot, q, v, h, steps):
    """Pinocchio's joint trajectory by the classical RK-4 (pin.integrate for the continuous joints)."""
    model = robot.model
    out = [(q.copy(), v.copy())]
    for _ in range(steps):
        k1v, k1a = v, robot.acceleration(q, v)
        q2, v2 = pin.integrate(model, q, k1v * h / 2), v + k1a * h / 2
        k2v, k2a = v2, robot.acceleration(q2, v2)
        q3, v3 = pin.integrate(model, q, k2v * h / 2), v + k2a * h / 2
        k3v, k3a = v3, robot.acceleration(q3, v3)
        q4, v4 = pin.integrate(model, q, k3v * h), v + k3a * h
        k4v, k4a = v4, robot.acceleration(q4, v4)
        q = pin.integrate(model, q, (k1v + 2 * k2v + 2 * k3v + k4v) * h / 6)
        v = v + (k1a + 2 * k2a + 2 * k3a + k4a) * h / 6
        out.append((q.copy(), v.copy()))
    return out


def angles(robot, q):
    """Joint coordinates of Pinocchio's q, one per velocity."""
    theta = np.zeros(robot.model.nv)
    for jm in robot.model.joints[1:]:
        if jm.nq == 2:
            theta[jm.idx_v] = np.arctan2(q[jm.idx_q + 1], q[jm.idx_q])
        elif jm.nq == 1:
            theta[jm.idx_v] = q[jm.idx_q]
    return theta


H = 1e-4


def run_beside_pinocchio(robot, t_end, joints, coordinates):
    """`cdyn run` of the robot from its zero pose (`joints` set) in
    `coordinates`, sampled every 100 steps of H, and Pinocchio's RK-4 from
    the same state at the same samples."""
    model = {"kind": "spatial", "urdf": str(robot.path), "gravity": GRAVITY, "coordinates": coordinates}
    scenario = {"model": model, "integrator": {"scheme": "rk4", "h": H, "t_end": t_end}, "output": {"every": 100}}
    q0 = pin.neutral(robot.model)
    if joints:
        scenario["initial"] = {"joints": joints}
        for name, value in joints.items():
            q0[robot.model.joints[robot.model.getJointId(name)].idx_q] = value
    result = cdyn.run(cdyn.from_dict(scenario))
    assert result.error is None, result.error
    reference = rk4_in_joint_space(robot, q0, np.zeros(robot.model.nv), H, round(t_end / H))[::100]
    assert len(reference) == len(result.q)
    return result, reference


# The 1 s at h = 1e-4 for UR5 (6 s in CI with the dev-profile
# wheel). SO-100 and Panda fall faster (light links; 3.1 rad in 1 s), and
# over 1 s the two RK-4 solutions — one in joint coordinates, one in
# redundant coordinates — differ by their truncation errors: |Δθ| =
# 5.3e-5, 3.3e-6, 2.1e-7 (SO-100) and 6.5e-8, 4.1e-9, 2.5e-10 (Panda) at
# h = 2e-4, 1e-4, 5e-5, a factor 16 per halving, so fourth order and not
# a disagreement in the physics. Over 0.05 s (500 steps) they agree to
# 1e-8 at h = 1e-4.
# cdyn run holds the limits: SO-100's zero pose has two joints at a bound
# (shoulder_lift at its lower 0, elbow_flex at its upper 0), which gravity
# would hold it against, so it starts inside its range (`[initial]
# joints`, and Pinocchio's q likewise); Panda's zero pose has joint 4
# outside its range (−3.07 to −0.07 rad), so it starts at −1.5 there, its
# fingers resting at their lower bound 0 (with nothing along them: held
# by no stop, they stay there as Pinocchio's free ones do).
TRAJECTORIES = [
    (UR5, 1.0, {}),
    (SO100, 0.05, {"shoulder_lift": 1.0, "elbow_flex": -1.0}),
    (PANDA, 0.05, {"panda_joint4": -1.5}),
]


@pytest.mark.parametrize("relative, t_end, joints", TRAJECTORIES)
def test_joint_trajectories_agree_with_pinocchio(relative, t_end, joints):
    robot = Robot(relative)
    result, reference = run_beside_pinocchio(robot, t_end, joints, "bodies")
    joints = robot.cdyn_joints(result.q, result.v)
    worst, travel = np.zeros(2), 0.0
    for name, values in joints.items():
        k, m = robot.index(name)
        for (q, v), (t, t_dot, _) in zip(reference, values):
            worst = np.maximum(worst, [abs(wrapped(t - m * angles(robot, q)[k])), abs(t_dot - m * v[k])])
            travel = max(travel, abs(t - values[0][0]))
    print(relative, "travel", travel, "worst |Δθ|, |Δθ̇|", worst)
    assert travel > 1e-3  # the robot moved from its start
    assert worst[0] < 1e-8 and worst[1] < 1e-8, worst


@pytest.mark.parametrize("relative, t_end, joints", TRAJECTORIES)
def test_joint_coordinate_runs_follow_pinocchio_to_round_off(relative, t_end, joints):
    """`coordinates = "joints"`: the same RK-4 in the same coordinates as
    Pinocchio's, so the runs agree to round-off, not to truncation error."""
    robot = Robot(relative)
    result, reference = run_beside_pinocchio(robot, t_end, joints, "joints")
    names, _, _ = _cdyn.urdf_tree(str(robot.path), GRAVITY, [], [])
    worst, travel = np.zeros(2), 0.0
    for c, name in enumerate(names):
        k, m = robot.index(name)
        for (q, v), theta, rate in zip(reference, result.q, result.v):
            worst = np.maximum(worst, [abs(theta[c] - m * angles(robot, q)[k]), abs(rate[c] - m * v[k])])
            travel = max(travel, abs(theta[c] - result.q[0][c]))
    print(relative, "travel", travel, "worst |Δθ|, |Δθ̇|", worst)
    assert travel > 1e-3
    assert worst[0] < 1e-11 and worst[1] < 1e-10, worst


# Z1's joints have regularized Coulomb friction (slip 0.01 rad/s) on light
# wrist links: too stiff for RK-4 at H, whose refusal names
# generalized_alpha, which then takes it (its Newton iteration damped
# across the friction law's knee). Halving its step moves the joints by
# its O(h²) error only.
def test_z1s_friction_refuses_rk4_and_runs_under_generalized_alpha():
    robot = Robot(Z1)

    def run(scheme, h):
        scenario = {
            "model": {"kind": "spatial", "urdf": str(robot.path), "gravity": GRAVITY},
            "integrator": {"scheme": scheme, "h": h, "t_end": 0.05},
            "output": {"every": round(0.01 / h)},
        }
        return cdyn.run(cdyn.from_dict(scenario))

    with pytest.raises(Exception, match="generalized_alpha"):
        run("rk4", H)
    coarse, fine = run("generalized_alpha", H), run("generalized_alpha", H / 2)
    assert coarse.error is None and fine.error is None, (coarse.error, fine.error)
    a, b = robot.cdyn_joints(coarse.q, coarse.v), robot.cdyn_joints(fine.q, fine.v)
    travel = max(abs(values[-1][0] - values[0][0]) for values in a.values())
    gap = max(abs(wrapped(x[0] - y[0])) for name in a for x, y in zip(a[name], b[name]))
    print("Z1 travel", travel, "h against h/2", gap)
    assert travel > 1e-3 and gap < 1e-3 * travel, (travel, gap)


def test_panda_at_its_zero_pose_is_refused_past_joint_4s_limit():
    scenario = cdyn.from_dict(
        {
            "model": {"kind": "spatial", "urdf": str(Robot(PANDA).path), "gravity": GRAVITY},
            "integrator": {"scheme": "rk4", "h": H, "t_end": 0.01},
        }
    )
    with pytest.raises(Exception, match="joint panda_joint4: starts 6.980e-2 past its upper limit -0.0698"):
        cdyn.run(scenario)


# example-robot-data 6.0.0 holds 69 URDF files; 59 load. A handful of each
# kind, with what cdyn counts as their joints (revolute and prismatic,
# a <mimic> one included) against Pinocchio's.
LOADS = [
    UR5,
    PANDA,
    Z1,
    KINOVA,
    SO100,
    XARM7,
    "double_pendulum_description/urdf/double_pendulum.urdf",
    "talos_data/robots/talos_left_arm.urdf",
    "tiago_description/robots/tiago.urdf",
    "pr2_description/urdf/pr2.urdf",  # links of unphysical inertia welded into physical bodies
]
REFUSED = [
    ("human_description/robots/human.urdf", 'link "left_upperleg_virtual": has no mass'),
    ("romeo_description/urdf/romeo_small.urdf", 'link "RShoulderYawLink": inertia is not physical'),
    ("ur_description/urdf/ur3.urdf", "no root link (the joints form a loop)"),
    ("icub_description/robots/icub.urdf", "not a valid URDF: custom: missing field `filename`"),
    ("iris_description/robots/iris_simple.urdf", "no body moves"),  # every link welded to the root
]


@pytest.mark.parametrize("relative", LOADS)
def test_common_robots_load_with_every_joint(relative):
    path = ROBOTS / relative
    bodies, q0, v0, names, _, _ = _cdyn.urdf_joints(str(path), GRAVITY, [], [])
    model = pin.buildModelFromUrdf(str(path))  # mimic joints as free ones: all joints counted
    assert len(q0) == len(v0) == 7 * len(bodies) > 0
    moving = [n for n, j in zip(model.names[1:], model.joints[1:]) if j.nv == 1]
    assert sorted(names) == sorted(moving)


@pytest.mark.parametrize("relative, reason", REFUSED)
def test_robots_cdyn_cannot_build_are_refused_with_the_element_and_the_reason(relative, reason):
    with pytest.raises(cdyn.ScenarioError) as refused:
        _cdyn.urdf_joints(str(ROBOTS / relative), GRAVITY, [], [])
    message = str(refused.value)
    assert message.startswith(str(ROBOTS / relative)) and reason in message and "\n" not in message
