//! URDF robots (`spatial::from_urdf`): the shipped arm in redundant
//! coordinates against the same arm's joint-space dynamics, computed here
//! from the URDF's numbers (forward kinematics, `T(θ, θ̇)` and `V(θ)`, the
//! elbow's damping as `−c θ̇`), and bad files refused with the element named.
#![cfg(feature = "urdf")]

use cdyn::model::kinetic::Kinetic;
use cdyn::spatial::{SpatialBody, from_urdf};
use cdyn::{Control, Error, Force, Model, Potential, Scalar, Scheme, Settings, Simulation, methods};

const ARM: &str = include_str!("../../../examples/arm.urdf");
const G: f64 = 9.81;

type M3<D> = [[D; 3]; 3];

fn mat_mul<D: Scalar>(a: &M3<D>, b: &M3<D>) -> M3<D> {
    std::array::from_fn(|i| std::array::from_fn(|j| a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j]))
}
fn mat_vec<D: Scalar>(a: &M3<D>, x: &[D; 3]) -> [D; 3] {
    std::array::from_fn(|i| a[i][0] * x[0] + a[i][1] * x[1] + a[i][2] * x[2])
}
fn cross<D: Scalar>(a: &[D; 3], b: &[D; 3]) -> [D; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}
fn constant<D: Scalar>(m: [[f64; 3]; 3]) -> M3<D> {
    m.map(|r| r.map(D::from))
}
/// Rotation by `angle` about the unit `axis` (Rodrigues).
fn axis_angle<D: Scalar>(axis: [f64; 3], angle: D) -> M3<D> {
    let (s, c) = (angle.sin(), angle.cos());
    std::array::from_fn(|i| {
        std::array::from_fn(|j| {
            let k = [[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]];
            let kk = (0..3).map(|m| k[i][m] * k[m][j]).sum::<f64>();
            let id = if i == j { 1.0 } else { 0.0 };
            (c * -1.0 + 1.0) * kk + s * k[i][j] + D::from(id)
        })
    })
}
/// URDF's `rpy`: `Rz(yaw) Ry(pitch) Rx(roll)`.
fn rpy([r, p, y]: [f64; 3]) -> [[f64; 3]; 3] {
    let m = |axis, a| axis_angle::<f64>(axis, a);
    mat_mul(&m([0.0, 0.0, 1.0], y), &mat_mul(&m([0.0, 1.0, 0.0], p), &m([1.0, 0.0, 0.0], r)))
}

/// The arm's numbers, as in `arm.urdf`: per joint the origin (xyz, rpy)
/// and unit axis; per link the mass, inertial origin (xyz, rpy) and inertia.
struct Link {
    joint_xyz: [f64; 3],
    joint_rpy: [f64; 3],
    axis: [f64; 3],
    mass: f64,
    com: [f64; 3],
    com_rpy: [f64; 3],
    inertia: [[f64; 3]; 3],
}

fn links() -> [Link; 3] {
    [
        Link {
            joint_xyz: [0.0, 0.0, 0.1],
            joint_rpy: [0.0; 3],
            axis: [0.0, 0.0, 1.0],
            mass: 2.0,
            com: [0.0, 0.0, 0.15],
            com_rpy: [0.0; 3],
            inertia: [[0.02, 0.001, 0.0], [0.001, 0.02, 0.0], [0.0, 0.0, 0.005]],
        },
        Link {
            joint_xyz: [0.0, 0.05, 0.3],
            joint_rpy: [0.3, 0.0, 0.0],
            axis: [0.0, 1.0, 0.0],
            mass: 1.5,
            com: [0.2, 0.0, 0.0],
            com_rpy: [0.0, 0.2, 0.0],
            inertia: [[0.003, 0.0, 0.001], [0.0, 0.03, 0.0], [0.001, 0.0, 0.03]],
        },
        Link {
            joint_xyz: [0.4, 0.0, 0.0],
            joint_rpy: [0.0, 0.0, 0.5],
            axis: [0.6, 0.0, 0.8],
            mass: 0.8,
            com: [0.1, 0.0, 0.0],
            com_rpy: [0.0; 3],
            inertia: [[0.001, 0.0, 0.0], [0.0, 0.008, 0.0], [0.0, 0.0, 0.008]],
        },
    ]
}

/// A link at one state, in space: centre of mass, its velocity, the
/// angular velocity and the inertia tensor.
struct LinkState<D> {
    c: [D; 3],
    vc: [D; 3],
    w: [D; 3],
    inertia: M3<D>,
}

/// Each link at `θ` (with rates `θ̇`).
fn kinematics<D: Scalar>(theta: [D; 3], rate: [D; 3]) -> [LinkState<D>; 3] {
    let (mut r, mut o, mut w, mut v) = (constant::<D>(rpy([0.0; 3])), [D::zero(); 3], [D::zero(); 3], [D::zero(); 3]);
    let links = links();
    std::array::from_fn(|i| {
        let l = &links[i];
        // The joint's frame on the parent, then the rotation about its axis.
        let o_next = {
            let x = mat_vec(&r, &l.joint_xyz.map(D::from));
            std::array::from_fn(|k| o[k] + x[k])
        };
        let wv = cross(&w, &std::array::from_fn(|k| o_next[k] - o[k]));
        v = std::array::from_fn(|k| v[k] + wv[k]);
        r = mat_mul(&r, &constant(rpy(l.joint_rpy)));
        let axis = mat_vec(&r, &l.axis.map(D::from));
        w = std::array::from_fn(|k| w[k] + axis[k] * rate[i]);
        r = mat_mul(&r, &axis_angle(l.axis, theta[i]));
        o = o_next;
        let arm = mat_vec(&r, &l.com.map(D::from));
        let c: [D; 3] = std::array::from_fn(|k| o[k] + arm[k]);
        let vc = cross(&w, &arm);
        let rc = mat_mul(&r, &constant(rpy(l.com_rpy)));
        let rt: M3<D> = std::array::from_fn(|a| std::array::from_fn(|b| rc[b][a]));
        let inertia = mat_mul(&rc, &mat_mul(&constant(l.inertia), &rt));
        LinkState { c, vc: std::array::from_fn(|k| v[k] + vc[k]), w, inertia }
    })
}

struct ArmKinetic;
impl Kinetic<3> for ArmKinetic {
    fn energy<D: Scalar>(&self, theta: [D; 3], rate: [D; 3]) -> D {
        let links = links();
        kinematics(theta, rate).iter().zip(&links).fold(D::zero(), |t, (LinkState { vc, w, inertia, .. }, l)| {
            let jw = mat_vec(inertia, w);
            let trans = (vc[0] * vc[0] + vc[1] * vc[1] + vc[2] * vc[2]) * (0.5 * l.mass);
            t + trans + (w[0] * jw[0] + w[1] * jw[1] + w[2] * jw[2]) * 0.5
        })
    }
}

struct ArmWeight;
impl Potential<3> for ArmWeight {
    fn energy<D: Scalar>(&self, theta: [D; 3]) -> D {
        let links = links();
        kinematics(theta, [D::zero(); 3]).iter().zip(&links).fold(D::zero(), |v, (s, l)| v + s.c[2] * (l.mass * G))
    }
}

/// The elbow's `<dynamics damping="0.1">`.
struct ElbowDamping;
impl Force<1> for ElbowDamping {
    fn force<D: Scalar>(&self, _x: [D; 1], xd: [D; 1], _t: D) -> [D; 1] {
        [xd[0] * -0.1]
    }
}

/// The hand's centre of mass over time, every 10 ms up to `t_end`.
fn hand_path(
    model: &Model,
    q0: &[f64],
    v0: &[f64],
    h: f64,
    t_end: f64,
    control: Control,
    hand: impl Fn(&[f64]) -> [f64; 3],
) -> Vec<[f64; 3]> {
    let mut sim = Simulation::new(model, Settings::new(Scheme::RungeKutta4, h, control), q0, v0).unwrap();
    let mut path = Vec::new();
    sim.run::<Error>(t_end, (0.01 / h).round() as u64, |s| {
        path.push(hand(s.q()));
        Ok(())
    })
    .unwrap();
    path
}

#[test]
fn the_urdf_arm_in_redundant_coordinates_follows_its_joint_space_dynamics() {
    let mechanism = from_urdf(ARM, [0.0, 0.0, -G]).unwrap();
    let names: Vec<&str> = mechanism.bodies.iter().map(|b| b.name.as_str()).collect();
    assert_eq!(names, ["upper", "fore", "hand"], "the massless base and tool are no bodies");
    assert_eq!(mechanism.joints.len(), 3);
    assert_eq!(mechanism.joints[1].damping, 0.1, "the elbow's damping is its joint's");
    let built = mechanism.build().unwrap();
    let joint_space = Model::builder(vec![0.0; 3])
        .kinetic(ArmKinetic, [0, 1, 2])
        .potential(ArmWeight, [0, 1, 2])
        .force(ElbowDamping, [1])
        .build()
        .unwrap();
    // The same pose at θ = 0: every centre of mass where the URDF puts it.
    let start = kinematics([0.0; 3], [0.0; 3]);
    for (i, LinkState { c, .. }) in start.iter().enumerate() {
        let r = SpatialBody::of(i).position(&built.q0);
        assert!((0..3).all(|k| (r[k] - c[k]).abs() < 1e-14), "link {i}: {r:?} vs {c:?}");
    }
    let (t_end, h) = (1.0, 1e-3);
    let redundant = |h, control| {
        hand_path(&built.model, &built.q0, &built.v0, h, t_end, control, |q| SpatialBody::of(2).position(q))
    };
    let joints = hand_path(&joint_space, &[0.0; 3], &[0.0; 3], h, t_end, Control::none(), |q| {
        kinematics([q[0], q[1], q[2]], [0.0; 3])[2].c
    });
    let fine = hand_path(&joint_space, &[0.0; 3], &[0.0; 3], h / 4.0, t_end, Control::none(), |q| {
        kinematics([q[0], q[1], q[2]], [0.0; 3])[2].c
    });
    let gap = |a: &[[f64; 3]], b: &[[f64; 3]]| {
        a.iter().zip(b).map(|(x, y)| (0..3).map(|k| (x[k] - y[k]).abs()).fold(0.0, f64::max)).fold(0.0, f64::max)
    };
    let travel = gap(&joints, &vec![joints[0]; joints.len()]);
    let integration = gap(&joints, &fine);
    assert!(travel > 0.1, "the arm hardly moves: {travel}");
    let mut uncontrolled = f64::NAN;
    for (name, control) in [("none", Control::none()), ("robust", methods::robust())] {
        let (coarse, finer) = (gap(&redundant(h, control), &fine), gap(&redundant(h / 4.0, control), &fine));
        println!(
            "hand over 1 s (moves {travel:.3} m), RK-4: {name}, redundant against the fine joint-space run: {coarse:.2e} at h = {h}, {finer:.2e} at h/4; joint space's own error at h {integration:.2e}"
        );
        // One motion integrated twice: the gap is the redundant model's
        // integration error (none: 9.8e-7 → 3.8e-9, order 4.0), which meets
        // the joint-space reference's own (about 1e-10 at h/4) with robust
        // (6.2e-9 → 9.9e-11).
        assert!(finer < 1e-8 && coarse > finer, "{name}: {coarse:e} → {finer:e}");
        if name == "none" {
            assert!(coarse / finer > 100.0, "no fourth order: {coarse:e} → {finer:e}");
            uncontrolled = coarse;
        } else {
            assert!(coarse <= uncontrolled, "{name} {coarse:e} worse than none {uncontrolled:e}");
        }
    }
}

#[test]
fn urdf_visuals_are_placed_in_the_axes_of_the_body_that_carries_them() {
    use cdyn::spatial::Shape;
    let arm = from_urdf(ARM, [0.0, 0.0, -G]).unwrap();
    let close = |a: &[f64], b: &[f64]| a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-12);
    let [upper, fore, hand] = [0, 1, 2].map(|i| &arm.bodies[i].visuals[..]);
    // The upper arm's cylinder is centred on its centre of mass, in its axes.
    assert_eq!(upper.len(), 1);
    assert_eq!(upper[0].shape, Shape::Cylinder { radius: 0.04, length: 0.3 });
    assert!(close(&upper[0].position, &[0.0; 3]) && close(&upper[0].orientation, &[1.0, 0.0, 0.0, 0.0]));
    // The forearm's box is at its centre of mass too, but its inertial axes
    // are turned 0.2 rad about y from the link's: the box is turned back.
    assert!(close(&fore[0].position, &[0.0; 3]), "{:?}", fore[0]);
    assert!(close(&fore[0].orientation, &[(0.1f64).cos(), 0.0, -(0.1f64).sin(), 0.0]), "{:?}", fore[0]);
    // The massless tool's sphere rides on the hand, 0.25 − 0.1 along its x.
    assert_eq!(hand.len(), 1);
    assert_eq!(hand[0].shape, Shape::Sphere { radius: 0.05 });
    assert!(close(&hand[0].position, &[0.15, 0.0, 0.0]), "{:?}", hand[0]);
}

#[test]
fn bad_urdf_files_are_refused_naming_the_element() {
    let cases = [
        ("<robot name=\"x\"><link name=\"a\"/>", "not a valid URDF"),
        (&*ARM.replace("type=\"continuous\"", "type=\"planar\""), "joint \"wrist\": type planar is not supported"),
        (
            &*ARM
                .replace("<dynamics damping=\"0.1\" friction=\"0\"/>", "<dynamics damping=\"0.1\" friction=\"-0.5\"/>"),
            "friction = -0.5",
        ),
        (
            &*ARM.replace("<child link=\"fore\"/>", "<child link=\"elbow\"/>"),
            "joint \"shoulder_pitch\": link \"elbow\" does not exist",
        ),
        (
            &*ARM.replace("<mass value=\"0.8\"/>", "<mass value=\"0\"/>"),
            "link \"hand\": has no mass, nor has any link fixed to it, but joint \"wrist\" moves it",
        ),
        (&*ARM.replace("<mass value=\"0.8\"/>", "<mass value=\"-0.8\"/>"), "link \"hand\": mass = -0.8"),
        (
            &*ARM.replace(
                "ixx=\"0.001\" ixy=\"0\" ixz=\"0\" iyy=\"0.008\"",
                "ixx=\"0.001\" ixy=\"0\" ixz=\"0\" iyy=\"0.02\"",
            ),
            "link \"hand\": inertia is not physical",
        ),
        (&*ARM.replace("</robot>", "<link name=\"spare\"/></robot>"), "2 root links (base_link, spare)"),
        (
            &*ARM.replace("<axis xyz=\"0 1 0\"/>", "<axis xyz=\"0 0 0\"/>"),
            "joint \"shoulder_pitch\": axis [0.0, 0.0, 0.0] has zero length",
        ),
    ];
    let limited = |limit: &str| one_joint("revolute", "0 1 0", limit, "");
    let (inverted, nan) = (
        limited(r#"<limit lower="1" upper="-1" effort="1" velocity="1"/>"#),
        limited(r#"<limit lower="nan" upper="1" effort="1" velocity="1"/>"#),
    );
    let cases = cases.into_iter().chain([
        (&*inverted, "joint \"j\": limit lower = 1, upper = -1: lower is above upper"),
        (&*nan, "joint \"j\": limit lower = NaN, upper = 1: a bound is not a number"),
    ]);
    for (text, expected) in cases {
        let error = from_urdf(text, [0.0, 0.0, -G]).and_then(|m| m.build().map(|_| ())).unwrap_err().to_string();
        assert!(error.contains(expected), "{error:?} should contain {expected:?}");
        assert_eq!(error.lines().count(), 1, "{error:?}");
    }
}

/// A URDF of one link on a joint of `kind` along `axis` under the base,
/// with `extra` inside the joint and `more` links after it.
fn one_joint(kind: &str, axis: &str, extra: &str, more: &str) -> String {
    format!(
        r#"<robot name="one"><link name="base"/>
        <joint name="j" type="{kind}"><parent link="base"/><child link="block"/>
          <origin xyz="0 0 0.5"/><axis xyz="{axis}"/>{extra}</joint>
        <link name="block"><inertial><origin xyz="0.2 0 0"/><mass value="2"/>
          <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.02"/></inertial></link>{more}</robot>"#
    )
}

/// The joint's coordinate and rate after `t_end` of RK-4 from rest.
fn joint_after(text: &str, t_end: f64, h: f64) -> [f64; 3] {
    let mechanism = from_urdf(text, [0.0, 0.0, -G]).unwrap();
    let built = mechanism.build().unwrap();
    let mut sim =
        Simulation::new(&built.model, Settings::new(Scheme::RungeKutta4, h, methods::robust()), &built.q0, &built.v0)
            .unwrap();
    sim.run::<Error>(t_end, 1000, |_| Ok(())).unwrap();
    let a = vec![0.0; built.model.n()];
    mechanism.joint_coordinates(sim.q(), sim.v(), &a).unwrap()[0].unwrap()
}

#[test]
fn a_prismatic_joint_slides_against_its_damping_and_its_regularized_friction() {
    // A vertical slider of 2 kg under gravity (19.62 N). Damping c alone:
    // the rate tends to −m g / c (the joint's coordinate is the
    // displacement along +z). Friction μ above m g: it creeps at
    // s m g / √(μ² − (m g)²), s the slip rate; below, it slides at the
    // acceleration −(m g − μ) / m (to 0.5 % of μ once faster than 10 s).
    let weight = 2.0 * G;
    let damped = joint_after(&one_joint("prismatic", "0 0 1", r#"<dynamics damping="40"/>"#, ""), 1.0, 1e-3);
    assert!((damped[1] + weight / 40.0).abs() < 1e-6 * weight / 40.0, "{damped:?}");
    let mu = 25.0;
    let held = joint_after(&one_joint("prismatic", "0 0 1", &format!(r#"<dynamics friction="{mu}"/>"#), ""), 1.0, 1e-4);
    let creep = cdyn::spatial::FRICTION_SLIP * weight / (mu * mu - weight * weight).sqrt();
    assert!((held[1] + creep).abs() < 1e-6 * creep, "{held:?} against {creep}");
    let mu = 10.0;
    let slides =
        joint_after(&one_joint("prismatic", "0 0 1", &format!(r#"<dynamics friction="{mu}"/>"#), ""), 0.5, 1e-4);
    let expected = -(weight - mu) / 2.0 * 0.5;
    assert!((slides[1] - expected).abs() < 0.01 * expected.abs(), "{slides:?} against {expected}");
}

#[test]
fn a_revolute_joints_friction_stops_a_swing_that_its_damping_only_slows() {
    // The block's 0.2 m arm swings about y under gravity from horizontal.
    let free = joint_after(&one_joint("revolute", "0 1 0", "", ""), 0.3, 1e-3);
    let rubbed = joint_after(&one_joint("revolute", "0 1 0", r#"<dynamics friction="0.5"/>"#, ""), 0.3, 1e-4);
    // The weight's torque at the start is m g 0.2 = 3.9 N m: 0.5 N m of
    // friction slows it, and the rate stays of the free one's sign.
    assert!(free[1] > 0.0 && rubbed[1] > 0.0 && rubbed[1] < free[1], "{free:?} {rubbed:?}");
    // 5 N m holds the 3.9 N m weight to a creep at s τ / √(μ² − τ²).
    let held = joint_after(&one_joint("revolute", "0 1 0", r#"<dynamics friction="5"/>"#, ""), 0.3, 1e-4);
    let torque = 2.0 * G * 0.2;
    let creep = cdyn::spatial::FRICTION_SLIP * torque / (25.0 - torque * torque).sqrt();
    assert!((held[1] - creep).abs() < 1e-3 * creep, "{held:?} against {creep}");
}

#[test]
fn links_without_mass_or_inertia_join_the_link_they_are_fixed_to_and_a_welds_zero_axis_is_ignored() {
    // A point mass (zero inertia) and a massless frame fixed to the block,
    // the frame's joint with a zero axis: one body, of the summed mass and
    // inertia about the common centre of mass.
    let more = r#"<joint name="tip" type="fixed"><parent link="block"/><child link="weight"/>
          <origin xyz="0.4 0 0"/><axis xyz="0 0 0"/></joint>
        <link name="weight"><inertial><mass value="1"/>
          <inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial></link>
        <joint name="frame" type="fixed"><parent link="weight"/><child link="camera"/><axis xyz="0 0 0"/></joint>
        <link name="camera"/>"#;
    let robot = cdyn::spatial::read_urdf(&one_joint("revolute", "0 1 0", "", more), [0.0, 0.0, -G]).unwrap();
    let m = &robot.mechanism;
    assert_eq!((m.bodies.len(), m.joints.len()), (1, 1), "{:?}", m.bodies);
    let body = &m.bodies[0];
    // Masses 2 at x = 0.2 and 1 at x = 0.4: centre at x = 0.8/3; the point
    // adds m d² about y and z: 2 (0.2 − c)² + 1 (0.4 − c)².
    let c = 0.8 / 3.0;
    let parallel = 2.0 * (0.2f64 - c).powi(2) + (0.4f64 - c).powi(2);
    assert_eq!(body.mass, 3.0);
    assert!((body.position[0] - c).abs() < 1e-15 && (body.position[2] - 0.5).abs() < 1e-15, "{:?}", body.position);
    for (k, own) in [0.01, 0.02 + parallel, 0.02 + parallel].into_iter().enumerate() {
        assert!((body.inertia[k][k] - own).abs() < 1e-15, "{k}: {:?}", body.inertia);
    }
    assert!(robot.notes.iter().any(|n| n.contains("2 links merged")), "{:?}", robot.notes);
    m.build().unwrap();
    // Moved by a joint, a point mass with nothing fixed to it is refused.
    let point = one_joint("revolute", "0 1 0", "", "").replace(
        r#"ixx="0.01" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.02""#,
        r#"ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0""#,
    );
    let error = from_urdf(&point, [0.0; 3]).unwrap_err().to_string();
    assert!(error.contains("link \"block\": inertia must be positive definite, and joint \"j\" moves it"), "{error}");
}

#[test]
fn a_massive_link_welded_to_a_moving_one_joins_its_body_with_the_same_dynamics_and_keeps_its_name() {
    // A tool of 1 kg, its own inertia turned (rpy), welded 0.4 m out on the
    // swinging block: from URDF one body; built by hand, the block and the
    // tool as two bodies held by a fixed joint. The joint's acceleration at
    // a turned, moving state is the same to round-off.
    let tool = r#"<joint name="mount" type="fixed"><parent link="block"/><child link="tool"/>
          <origin xyz="0.4 0 0" rpy="0.3 0 0"/></joint>
        <link name="tool"><inertial><origin xyz="0 0.05 0" rpy="0 0.2 0"/><mass value="1"/>
          <inertia ixx="0.003" ixy="0" ixz="0" iyy="0.004" iyz="0" izz="0.005"/></inertial></link>"#;
    let g = [0.0, 0.0, -G];
    let robot = cdyn::spatial::read_urdf(&one_joint("revolute", "0 1 0", "", tool), g).unwrap();
    assert_eq!(robot.mechanism.bodies.len(), 1, "{:?}", robot.mechanism.bodies);
    assert!(robot.notes.iter().any(|n| n.contains("1 links merged")), "{:?}", robot.notes);
    let merged = &robot.merged;
    assert_eq!(merged.iter().map(|l| (l.name.as_str(), l.body.as_str())).collect::<Vec<_>>(), [("tool", "block")]);
    // The tool's centre: 0.4 along x from the joint at z = 0.5, then 0.05
    // along the mount's y turned by roll 0.3 about x.
    let centre = [0.4, 0.05 * 0.3f64.cos(), 0.5 + 0.05 * 0.3f64.sin()];
    let found = merged[0].centre.unwrap();
    assert!((0..3).all(|k| (found[k] - centre[k]).abs() < 1e-15), "{found:?} vs {centre:?}");

    // By hand: the tool's body at its centre, in the axes roll 0.3 then pitch 0.2.
    let block = from_urdf(&one_joint("revolute", "0 1 0", "", ""), g).unwrap();
    let half = |a: f64| ((a / 2.0).cos(), (a / 2.0).sin());
    let ((cr, sr), (cp, sp)) = (half(0.3), half(0.2));
    let axes = [cr * cp, sr * cp, cr * sp, sr * sp];
    let body =
        cdyn::spatial::Body::new("tool", 1.0, [0.003, 0.004, 0.005]).with_position(centre).with_orientation(axes);
    let weld = cdyn::spatial::Joint::new(cdyn::spatial::JointKind::Fixed, 1, Some(0), [0.4, 0.0, 0.5])
        .with_axis([0.0, 0.0, 1.0]);
    let two =
        block.clone().with_bodies(vec![block.bodies[0].clone(), body]).with_joints(vec![block.joints[0].clone(), weld]);
    let acceleration = |m: &cdyn::spatial::Mechanism| {
        let (q, v) = m.state_at_joints(&[(0, 0.3)], &[(0, -0.7)]).unwrap();
        let built = m.build().unwrap();
        let mut d = cdyn::dynamics::Dynamics::new(&built.model);
        d.evaluate(&built.model, &q, &v, 0.0).unwrap();
        m.joint_coordinates(&q, &v, d.acc()).unwrap()[0].unwrap()
    };
    let (one, apart) = (acceleration(&robot.mechanism), acceleration(&two));
    println!("welded tool: θ, θ̇, θ̈ merged {one:?}, two bodies {apart:?}");
    assert!((0..3).all(|k| (one[k] - apart[k]).abs() < 1e-12 * (1.0 + apart[k].abs())), "{one:?} vs {apart:?}");

    // A force on the tool without a point acts at the tool's centre of mass.
    use cdyn::spatial::{Load, Mechanism};
    let named = |load: Load<String>| {
        let m = &robot.mechanism;
        let joints = m.joints.iter().map(|j| j.clone().map_bodies(|b| m.bodies[b].name.clone())).collect();
        Mechanism::named_with_links(m.bodies.clone(), joints, vec![load], g, merged).unwrap()
    };
    let on_tool = named(Load::Force { body: "tool".into(), force: [0.0, 0.0, 5.0], point: None });
    let at_centre = named(Load::Force { body: "block".into(), force: [0.0, 0.0, 5.0], point: Some(found) });
    assert_eq!(on_tool.loads, at_centre.loads);
    assert_ne!(acceleration(&on_tool), one, "the force acts");
}

#[test]
fn a_mimic_joint_follows_its_leader_and_what_is_not_modelled_is_listed() {
    // A second block on the first, its joint at half the first's angle plus 0.
    let more = r#"<joint name="k" type="revolute"><parent link="block"/><child link="tip"/>
          <origin xyz="0.4 0 0"/><axis xyz="0 1 0"/><mimic joint="j" multiplier="0.5"/>
          <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
        <link name="tip"><inertial><origin xyz="0.1 0 0"/><mass value="1"/>
          <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
          <collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision></link>
        <transmission name="t"/>"#;
    let text = one_joint("revolute", "0 1 0", "", more);
    let robot = cdyn::spatial::read_urdf(&text, [0.0, 0.0, -G]).unwrap();
    assert_eq!(robot.mechanism.couplings, [cdyn::spatial::Coupling::new(1, 0, 0.5, 0.0)]);
    assert_eq!(robot.notes[..2], ["collision (no contact) (1 element)", "transmission (1 element)"]);
    let built = robot.mechanism.build().unwrap();
    let mut sim = Simulation::new(
        &built.model,
        Settings::new(Scheme::RungeKutta4, 1e-3, methods::robust()),
        &built.q0,
        &built.v0,
    )
    .unwrap();
    sim.run::<Error>(0.5, 100, |_| Ok(())).unwrap();
    let a = vec![0.0; built.model.n()];
    let theta = robot.mechanism.joint_coordinates(sim.q(), sim.v(), &a).unwrap();
    let ([j, jd, _], [k, kd, _]) = (theta[0].unwrap(), theta[1].unwrap());
    assert!(j.abs() > 0.5, "it swings: {j}");
    assert!((k - 0.5 * j).abs() < 1e-9 && (kd - 0.5 * jd).abs() < 1e-9, "{theta:?}");
    let bad = text.replace(r#"<mimic joint="j""#, r#"<mimic joint="nope""#);
    let error = from_urdf(&bad, [0.0; 3]).unwrap_err().to_string();
    assert!(
        error.contains("joint \"k\": <mimic joint=\"nope\">: no revolute or prismatic joint of that name"),
        "{error}"
    );
}

#[test]
fn a_urdf_limit_stops_its_joint_and_holds_it() {
    // The block falls about y (θ grows), onto its upper limit at 0.5 rad,
    // where its weight keeps it: one impact, held to the end.
    let text = one_joint("revolute", "0 1 0", r#"<limit lower="-0.2" upper="0.5" effort="3" velocity="2"/>"#, "");
    let robot = cdyn::spatial::read_urdf(&text, [0.0, 0.0, -G]).unwrap();
    let limit = robot.mechanism.joints[0].limit.unwrap();
    assert_eq!((limit.lower, limit.upper, limit.velocity, limit.effort), (-0.2, 0.5, 2.0, 3.0));
    // The effort bound is the actuator's clamp, not an unmodelled element.
    assert!(robot.notes.iter().all(|n| !n.contains("effort")), "{:?}", robot.notes);
    let (mechanism, built) = (&robot.mechanism, robot.mechanism.build().unwrap());
    let stops = cdyn::stops::MechanismStops::new(mechanism.clone()).unwrap();
    let settings = Settings::new(Scheme::RungeKutta4, 1e-3, methods::robust());
    let mut last = [0.0; 3];
    let report =
        cdyn::stops::run_with_stops::<_, Error>(&stops, settings, &built.q0, &built.v0, 1.0, 100, |_, q, v| {
            last = mechanism.joint_coordinates(q, v, &vec![0.0; q.len()])?[0].unwrap();
            Ok(())
        })
        .unwrap();
    let events = &report.events;
    assert_eq!(events.len(), 1, "{events:?}");
    assert!(matches!(events[0].change, cdyn::stops::Change::Impact { held: true, .. }));
    // Its velocity bound, 2 rad/s, is passed on the way down (reported, not enforced).
    let [(0, ratio, t)] = report.overspeed[..] else { panic!("{:?}", report.overspeed) };
    assert!(ratio > 1.0 && t < events[0].t, "{ratio} at {t}");
    assert!((last[0] - 0.5).abs() < 1e-9 && last[1].abs() < 1e-9, "{last:?}");
}

#[test]
fn the_arm_started_at_given_joint_angles_and_rates_reads_them_back() {
    // Forward kinematics over the joint tree places the links exactly: the
    // joints read back the given values to round-off, and every constraint
    // row holds (Φ and Φ̇ = Φ_q v at round-off), so no assembly is needed.
    let mechanism = from_urdf(ARM, [0.0, 0.0, -G]).unwrap();
    let angles = [(0, 0.7), (1, -1.1), (2, 2.5)];
    let rates = [(0, -0.4), (1, 1.3), (2, 0.9)];
    let (q, v) = mechanism.state_at_joints(&angles, &rates).unwrap();
    let read = mechanism.joint_coordinates(&q, &v, &vec![0.0; q.len()]).unwrap();
    for ((joint, angle), (_, rate)) in angles.iter().zip(&rates) {
        let [theta, theta_dot, _] = read[*joint].unwrap();
        assert!((theta - angle).abs() < 1e-14 && (theta_dot - rate).abs() < 1e-14, "{joint}: {theta} {theta_dot}");
    }
    let built = mechanism.build().unwrap();
    let mut phi = vec![0.0; built.model.m()];
    built.model.constraint_values(&q, 0.0, &mut phi);
    let phi_dot = {
        let h = 1e-7;
        let ahead: Vec<f64> = q.iter().zip(&v).map(|(q, v)| q + h * v).collect();
        let mut next = vec![0.0; built.model.m()];
        built.model.constraint_values(&ahead, h, &mut next);
        next.iter().zip(&phi).fold(0.0_f64, |m, (b, a)| m.max(((b - a) / h).abs()))
    };
    let worst = phi.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
    assert!(worst < 1e-14 && phi_dot < 1e-6, "|Φ| {worst:e}, |Φ̇| {phi_dot:e}");
    // A joint that does not exist is refused.
    let error = mechanism.state_at_joints(&[(mechanism.joints.len(), 0.1)], &[]).unwrap_err().to_string();
    assert!(error.contains("joint"), "{error}");
}

#[test]
fn a_base_welded_to_the_root_is_part_of_the_ground_and_drawn_there() {
    use cdyn::spatial::Shape;
    // world → (fixed, 0.2 up, turned 1 rad about z) → base, 4 kg, a box
    // 0.1 out along its x; base → (fixed) → plate, 6 kg, only a mesh; the
    // block swings on a revolute joint from the base.
    let base = r#"<link name="world"/>
        <joint name="mount" type="fixed"><parent link="world"/><child link="base"/><origin xyz="0 0 0.2" rpy="0 0 1"/></joint>
        <link name="base"><inertial><mass value="4"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial>
          <visual><origin xyz="0.1 0 0"/><geometry><box size="0.3 0.2 0.1"/></geometry></visual></link>
        <joint name="bolt" type="fixed"><parent link="base"/><child link="plate"/><origin xyz="0 0 -0.1"/></joint>
        <link name="plate"><inertial><mass value="6"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.03"/></inertial>
          <visual><geometry><mesh filename="plate.stl"/></geometry></visual></link>"#;
    let massless = one_joint("revolute", "0 1 0", "", "");
    let text = massless
        .replace(r#"<link name="base"/>"#, base)
        .replace(r#"<parent link="base"/><child link="block"/>"#, r#"<parent link="plate"/><child link="block"/>"#);
    let robot = cdyn::spatial::read_urdf(&text, [0.0, 0.0, -G]).unwrap();
    let m = &robot.mechanism;
    assert_eq!(m.bodies.iter().map(|b| b.name.as_str()).collect::<Vec<_>>(), ["block"]);
    assert_eq!((m.joints.len(), m.joints[0].b), (1, None), "the block's joint is to the ground");
    let grounded: Vec<(&str, &str)> = robot.merged.iter().map(|l| (l.name.as_str(), l.body.as_str())).collect();
    assert_eq!(grounded, [("base", "ground"), ("plate", "ground")]);
    // On the ground, in space: the base's box, turned with it; the plate's
    // box of uniform density with its inertia (sides² = 6 (J₂ + J₃ − J₁) / m
    // and cyclically: 0.04, 0.02, 0), at its centre.
    let close = |a: &[f64], b: &[f64]| a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-12);
    let [boxed, plate] = &m.ground[..] else { panic!("{:?}", m.ground) };
    assert_eq!(boxed.shape, Shape::Box { size: [0.3, 0.2, 0.1] });
    assert!(close(&boxed.position, &[0.1 * 1f64.cos(), 0.1 * 1f64.sin(), 0.2]), "{boxed:?}");
    assert!(close(&boxed.orientation, &[0.5f64.cos(), 0.0, 0.0, 0.5f64.sin()]), "{boxed:?}");
    let Shape::Box { mut size } = plate.shape else { panic!("{plate:?}") };
    size.sort_by(f64::total_cmp);
    assert!(close(&size, &[0.0, 0.02f64.sqrt(), 0.2]) && close(&plate.position, &[0.0, 0.0, 0.1]), "{plate:?}");
    assert_eq!(m.sketch().ground, m.ground);
    // Nothing of the base moves, so its masses change nothing: the same
    // motion, to the bit, as with a massless base and plate.
    let weightless = text
        .replace(r#"<inertial><mass value="4"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial>"#, "")
        .replace(r#"<inertial><mass value="6"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.03"/></inertial>"#, "");
    assert_eq!(from_urdf(&weightless, [0.0; 3]).unwrap().bodies.len(), 1);
    assert_eq!(joint_after(&text, 0.5, 1e-3), joint_after(&weightless, 0.5, 1e-3));
    // With the block welded too, nothing moves: refused, saying so.
    let still = from_urdf(&text.replace(r#"type="revolute""#, r#"type="fixed""#), [0.0; 3]).unwrap();
    assert!(still.bodies.is_empty() && still.ground.len() == 3, "the block drawn on the ground too");
    let Err(error) = still.build() else { panic!("nothing moves, yet it built") };
    let error = error.to_string();
    assert!(error.contains("no body moves") && !error.contains('\n'), "{error}");
}
