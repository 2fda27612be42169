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
    assert_eq!(mechanism.loads.len(), 1);
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
            &*ARM.replace("<dynamics damping=\"0.1\" friction=\"0\"/>", "<dynamics damping=\"0.1\" friction=\"0.5\"/>"),
            "joint \"shoulder_pitch\": friction = 0.5",
        ),
        (
            &*ARM.replace("<child link=\"fore\"/>", "<child link=\"elbow\"/>"),
            "joint \"shoulder_pitch\": link \"elbow\" does not exist",
        ),
        (
            &*ARM.replace("<mass value=\"0.8\"/>", "<mass value=\"0\"/>"),
            "link \"hand\": has no mass but joint \"wrist\" moves it",
        ),
        (&*ARM.replace("<mass value=\"0.8\"/>", "<mass value=\"-0.8\"/>"), "body 2 (hand): mass = -0.8"),
        (
            &*ARM.replace(
                "ixx=\"0.001\" ixy=\"0\" ixz=\"0\" iyy=\"0.008\"",
                "ixx=\"0.001\" ixy=\"0\" ixz=\"0\" iyy=\"0.02\"",
            ),
            "body 2 (hand): inertia is not physical",
        ),
        (&*ARM.replace("</robot>", "<link name=\"spare\"/></robot>"), "2 root links (base_link, spare)"),
        (
            &*ARM.replace("<axis xyz=\"0 1 0\"/>", "<axis xyz=\"0 0 0\"/>"),
            "joint \"shoulder_pitch\": axis [0.0, 0.0, 0.0] has zero length",
        ),
    ];
    for (text, expected) in cases {
        let error = from_urdf(text, [0.0, 0.0, -G]).and_then(|m| m.build().map(|_| ())).unwrap_err().to_string();
        assert!(error.contains(expected), "{error:?} should contain {expected:?}");
        assert_eq!(error.lines().count(), 1, "{error:?}");
    }
}
