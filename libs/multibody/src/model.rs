//! Loading, validating and describing the servicer model (base + 7-DoF serial arm) from URDF.

use std::collections::HashMap;
use std::path::Path;

use nalgebra::{Matrix3, SymmetricEigen, Vector3};

use crate::NJ;
use crate::error::ModelError;
use crate::spatial::{Inertia, Transform, rpy};

/// URDF limits of one revolute joint.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JointLimits {
    /// Lower position limit (rad).
    pub lower: f64,
    /// Upper position limit (rad).
    pub upper: f64,
    /// Velocity limit |θ̇| (rad/s).
    pub velocity: f64,
    /// Effort limit |τ| (N m).
    pub effort: f64,
}

/// One collision sphere of the model.
#[derive(Clone, Debug, PartialEq)]
pub struct CollisionSphere {
    /// Moving body carrying the sphere: 0 = base, `i` in 1..=7 = arm link after joint `i`.
    pub link: usize,
    /// Centre in the frame of that body (m).
    pub center: Vector3<f64>,
    /// Radius (m).
    pub radius: f64,
    /// Name of the URDF link that declares the sphere (may be a link fixed to `link`).
    pub urdf_link: String,
    /// Position of the sphere among the `<collision>` elements of `urdf_link` (0-based).
    pub urdf_index: usize,
}

/// A named frame rigidly attached to a moving body (one per URDF link).
#[derive(Clone, Debug, PartialEq)]
pub struct Frame {
    pub name: String,
    /// Moving body index (0 = base, 1..=7 = arm bodies).
    pub body: usize,
    /// Placement of the frame in the body frame.
    pub placement: Transform,
}

/// One revolute joint of the chain.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct RevJoint {
    pub name: String,
    /// Placement of the joint frame (at θ = 0) in the parent body frame.
    pub origin: Transform,
    /// Unit rotation axis in the joint (= child body) frame.
    pub axis: Vector3<f64>,
    pub limits: JointLimits,
}

/// The servicer as a free-flying multibody system: body 0 is the base (spacecraft bus),
/// bodies 1..=7 the arm links after joints 1..=7 (links fixed to a body are merged into it).
///
/// The base frame `F_B` is the frame of the URDF root link.
#[derive(Clone, Debug)]
pub struct Robot {
    pub(crate) name: String,
    pub(crate) body_names: [String; NJ + 1],
    pub(crate) inertias: [Inertia; NJ + 1],
    pub(crate) joints: Vec<RevJoint>,
    pub(crate) joint_names: Vec<String>,
    pub(crate) spheres: Vec<CollisionSphere>,
    pub(crate) frames: Vec<Frame>,
    pub(crate) ee_frame: usize,
    pub(crate) total_mass: f64,
}

fn finite3(element: &str, field: &'static str, v: &[f64; 3]) -> Result<(), ModelError> {
    for &x in v {
        if !x.is_finite() {
            return Err(ModelError::NonFinite {
                element: element.to_string(),
                field,
                value: x,
            });
        }
    }
    Ok(())
}

fn pose_to_transform(element: &str, pose: &urdf_rs::Pose) -> Result<Transform, ModelError> {
    finite3(element, "origin xyz", &pose.xyz.0)?;
    finite3(element, "origin rpy", &pose.rpy.0)?;
    let [x, y, z] = pose.xyz.0;
    let [r, p, yaw] = pose.rpy.0;
    Ok(Transform::new(rpy(r, p, yaw), Vector3::new(x, y, z)))
}

/// Validate a link inertial and return it as a spatial inertia in the LINK frame.
fn link_inertia(link: &urdf_rs::Link) -> Result<Inertia, ModelError> {
    let name = &link.name;
    let inertial = &link.inertial;
    let m = inertial.mass.value;
    if !m.is_finite() || m < 0.0 {
        return Err(ModelError::InvalidMass {
            link: name.clone(),
            value: m,
        });
    }
    let i = &inertial.inertia;
    let el = format!("link '{name}' inertia");
    for (field, v) in [
        ("ixx", i.ixx),
        ("ixy", i.ixy),
        ("ixz", i.ixz),
        ("iyy", i.iyy),
        ("iyz", i.iyz),
        ("izz", i.izz),
    ] {
        if !v.is_finite() {
            return Err(ModelError::NonFinite {
                element: el,
                field,
                value: v,
            });
        }
    }
    let ic = Matrix3::new(
        i.ixx, i.ixy, i.ixz, i.ixy, i.iyy, i.iyz, i.ixz, i.iyz, i.izz,
    );
    let eig = SymmetricEigen::new(ic).eigenvalues;
    let mut moments = [eig[0], eig[1], eig[2]];
    moments.sort_by(|a, b| a.total_cmp(b));
    if m == 0.0 {
        if ic.iter().any(|&v| v != 0.0) {
            return Err(ModelError::NonPositiveDefiniteInertia {
                link: name.clone(),
                moments,
            });
        }
    } else {
        let scale = moments[2].abs().max(f64::MIN_POSITIVE);
        if moments[0] <= 1e-12 * scale || moments[0] <= 0.0 {
            return Err(ModelError::NonPositiveDefiniteInertia {
                link: name.clone(),
                moments,
            });
        }
        // Sorted: the only binding permutation is I1 + I2 >= I3.
        if moments[0] + moments[1] < moments[2] * (1.0 - 1e-9) {
            return Err(ModelError::TriangleInequality {
                link: name.clone(),
                moments,
            });
        }
    }
    let frame = pose_to_transform(&format!("link '{name}' inertial"), &inertial.origin)?;
    let c = frame.trans;
    let ic_link = frame.rot * ic * frame.rot.transpose();
    Ok(Inertia::from_com(m, c, ic_link))
}

/// The URDF's links and joints as a tree: unique names, every joint between known links,
/// one parent per link, one root, [`NJ`] revolute joints and otherwise only fixed ones.
struct Tree<'a> {
    /// Index of each link by name.
    link_idx: HashMap<&'a str, usize>,
    /// The joints leaving each link.
    children: Vec<Vec<usize>>,
    /// The root link (the base).
    root: usize,
}

impl<'a> Tree<'a> {
    fn of(doc: &'a urdf_rs::Robot) -> Result<Self, ModelError> {
        let mut link_idx: HashMap<&str, usize> = HashMap::new();
        for (i, l) in doc.links.iter().enumerate() {
            if link_idx.insert(l.name.as_str(), i).is_some() {
                return Err(ModelError::DuplicateName {
                    what: "link",
                    name: l.name.clone(),
                });
            }
        }
        let mut joint_names_seen: HashMap<&str, ()> = HashMap::new();
        let mut parent_of: Vec<Option<usize>> = vec![None; doc.links.len()];
        let mut children: Vec<Vec<usize>> = vec![Vec::new(); doc.links.len()];
        let mut n_rev = 0usize;
        for (ji, j) in doc.joints.iter().enumerate() {
            if joint_names_seen.insert(j.name.as_str(), ()).is_some() {
                return Err(ModelError::DuplicateName {
                    what: "joint",
                    name: j.name.clone(),
                });
            }
            let lookup = |name: &str| {
                link_idx
                    .get(name)
                    .copied()
                    .ok_or_else(|| ModelError::UnknownLink {
                        joint: j.name.clone(),
                        link: name.to_string(),
                    })
            };
            let p = lookup(&j.parent.link)?;
            let c = lookup(&j.child.link)?;
            if parent_of[c].is_some() || c == p {
                return Err(ModelError::NotATree {
                    link: j.child.link.clone(),
                });
            }
            parent_of[c] = Some(ji);
            children[p].push(ji);
            if is_revolute(j)? {
                n_rev += 1;
            }
        }
        let root = single_root(doc, &parent_of)?;
        if n_rev != NJ {
            return Err(ModelError::JointCount {
                found: n_rev,
                expected: NJ,
            });
        }
        Ok(Tree {
            link_idx,
            children,
            root,
        })
    }
}

/// `true` for a revolute joint, `false` for a fixed one; other types are refused.
fn is_revolute(j: &urdf_rs::Joint) -> Result<bool, ModelError> {
    match j.joint_type {
        urdf_rs::JointType::Revolute => Ok(true),
        urdf_rs::JointType::Fixed => Ok(false),
        ref other => Err(ModelError::UnsupportedJoint {
            joint: j.name.clone(),
            kind: format!("{other:?}").to_lowercase(),
        }),
    }
}

/// The one link without a parent joint.
fn single_root(doc: &urdf_rs::Robot, parent_of: &[Option<usize>]) -> Result<usize, ModelError> {
    let roots: Vec<usize> = (0..doc.links.len())
        .filter(|&i| parent_of[i].is_none())
        .collect();
    if roots.len() != 1 {
        return Err(ModelError::RootCount {
            count: roots.len(),
            names: roots.iter().map(|&i| doc.links[i].name.clone()).collect(),
        });
    }
    Ok(roots[0])
}

/// The serial chain found by walking the tree from the root: the moving body of every link
/// and its placement in that body, the bodies' names and the [`NJ`] revolute joints in
/// chain order.
struct Chain {
    link_body: Vec<Option<(usize, Transform)>>,
    body_names: [String; NJ + 1],
    joints: Vec<RevJoint>,
}

impl Chain {
    fn walk(doc: &urdf_rs::Robot, tree: &Tree) -> Result<Self, ModelError> {
        let mut link_body: Vec<Option<(usize, Transform)>> = vec![None; doc.links.len()];
        link_body[tree.root] = Some((0, Transform::IDENTITY));
        let mut body_joint: [Option<usize>; NJ + 1] = [None; NJ + 1];
        let mut joints: Vec<Option<RevJoint>> = vec![None; NJ];
        let mut body_names: [String; NJ + 1] = Default::default();
        body_names[0] = doc.links[tree.root].name.clone();
        let mut stack = vec![tree.root];
        while let Some(li) = stack.pop() {
            let Some((body, place)) = link_body[li] else {
                continue;
            };
            for &ji in &tree.children[li] {
                let j = &doc.joints[ji];
                let ci = tree.link_idx[j.child.link.as_str()];
                let origin = pose_to_transform(&format!("joint '{}'", j.name), &j.origin)?;
                if j.joint_type == urdf_rs::JointType::Fixed {
                    link_body[ci] = Some((body, place.compose(&origin)));
                } else {
                    if body_joint[body].is_some() || body >= NJ {
                        return Err(ModelError::NotSerialChain {
                            joint: j.name.clone(),
                        });
                    }
                    body_joint[body] = Some(ji);
                    joints[body] = Some(rev_joint(j, place.compose(&origin))?);
                    link_body[ci] = Some((body + 1, Transform::IDENTITY));
                    body_names[body + 1] = j.child.link.clone();
                }
                stack.push(ci);
            }
        }
        let disconnected: Vec<String> = (0..doc.links.len())
            .filter(|&i| link_body[i].is_none())
            .map(|i| doc.links[i].name.clone())
            .collect();
        if !disconnected.is_empty() {
            return Err(ModelError::Disconnected {
                names: disconnected,
            });
        }
        // Cycles are impossible (each link has at most one parent and one root is reachable).
        let mut rev = Vec::with_capacity(NJ);
        for (k, j) in joints.into_iter().enumerate() {
            match j {
                Some(j) => rev.push(j),
                None => {
                    // Fewer than NJ chained joints although NJ revolute joints exist: branch.
                    return Err(ModelError::NotSerialChain {
                        joint: format!("<missing joint after body {k}>"),
                    });
                }
            }
        }
        Ok(Chain {
            link_body,
            body_names,
            joints: rev,
        })
    }
}

/// A revolute joint placed at `origin` in its parent body: axis non-zero (normalized here),
/// `lower ≤ upper`, velocity and effort limits > 0.
fn rev_joint(j: &urdf_rs::Joint, origin: Transform) -> Result<RevJoint, ModelError> {
    let el = format!("joint '{}'", j.name);
    finite3(&el, "axis", &j.axis.xyz.0)?;
    let a = Vector3::from(j.axis.xyz.0);
    let n = a.norm();
    if n <= 1e-9 {
        return Err(ModelError::ZeroAxis {
            joint: j.name.clone(),
            axis: j.axis.xyz.0,
        });
    }
    let lim = &j.limit;
    if !lim.lower.is_finite() || !lim.upper.is_finite() || lim.lower > lim.upper {
        return Err(ModelError::LimitOrder {
            joint: j.name.clone(),
            lower: lim.lower,
            upper: lim.upper,
        });
    }
    if !lim.velocity.is_finite() || lim.velocity <= 0.0 {
        return Err(ModelError::InvalidVelocityLimit {
            joint: j.name.clone(),
            value: lim.velocity,
        });
    }
    if !lim.effort.is_finite() || lim.effort <= 0.0 {
        return Err(ModelError::InvalidEffortLimit {
            joint: j.name.clone(),
            value: lim.effort,
        });
    }
    Ok(RevJoint {
        name: j.name.clone(),
        origin,
        axis: a / n,
        limits: JointLimits {
            lower: lim.lower,
            upper: lim.upper,
            velocity: lim.velocity,
            effort: lim.effort,
        },
    })
}

/// What the links contribute to their moving bodies: the merged inertias, the collision
/// spheres (sorted by body, URDF order within a body) and one frame per link.
struct Bodies {
    inertias: [Inertia; NJ + 1],
    spheres: Vec<CollisionSphere>,
    frames: Vec<Frame>,
}

impl Bodies {
    fn gather(
        doc: &urdf_rs::Robot,
        link_body: &[Option<(usize, Transform)>],
    ) -> Result<Self, ModelError> {
        let mut inertias = [Inertia::ZERO; NJ + 1];
        let mut spheres = Vec::new();
        let mut frames = Vec::with_capacity(doc.links.len());
        for (li, link) in doc.links.iter().enumerate() {
            let Some((body, place)) = link_body[li] else {
                continue;
            };
            let inertia = link_inertia(link)?;
            inertias[body] = inertias[body].add(&inertia.transformed(&place));
            for (k, col) in link.collision.iter().enumerate() {
                spheres.push(collision_sphere(link, k, col, body, &place)?);
            }
            frames.push(Frame {
                name: link.name.clone(),
                body,
                placement: place,
            });
        }
        spheres.sort_by_key(|s| s.link); // stable: URDF order kept within a body
        Ok(Bodies {
            inertias,
            spheres,
            frames,
        })
    }
}

/// Collision element `k` of `link` (on moving body `body` at `place`): a sphere with
/// radius > 0.
fn collision_sphere(
    link: &urdf_rs::Link,
    k: usize,
    col: &urdf_rs::Collision,
    body: usize,
    place: &Transform,
) -> Result<CollisionSphere, ModelError> {
    let urdf_rs::Geometry::Sphere { radius } = col.geometry else {
        return Err(ModelError::InvalidCollision {
            link: link.name.clone(),
            index: k,
            detail: format!("geometry {:?} is not a sphere", col.geometry),
        });
    };
    if !radius.is_finite() || radius <= 0.0 {
        return Err(ModelError::InvalidCollision {
            link: link.name.clone(),
            index: k,
            detail: format!("radius {radius} m"),
        });
    }
    let o = pose_to_transform(&format!("link '{}' collision #{k}", link.name), &col.origin)?;
    Ok(CollisionSphere {
        link: body,
        center: place.act_point(&o.trans),
        radius,
        urdf_link: link.name.clone(),
        urdf_index: k,
    })
}

impl Robot {
    /// Load and validate a URDF file (see [`Robot::from_urdf_str`] for the rules).
    pub fn from_urdf_file(path: &Path) -> Result<Robot, ModelError> {
        let text = std::fs::read_to_string(path).map_err(|source| ModelError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Self::from_urdf_str(&text)
    }

    /// Parse and validate a URDF document.
    ///
    /// Rules: one root link (the base); exactly [`NJ`] `revolute` joints forming one serial
    /// chain from the root, any number of `fixed` joints (their links are merged into the moving
    /// body they hang on), no other joint types; masses finite and ≥ 0, inertias positive
    /// definite and satisfying the triangle inequality (or all zero for massless links); the base
    /// body and every arm body with mass > 0 after merging; joint axes non-zero (normalized
    /// here), `lower ≤ upper`, velocity and effort limits > 0; collision geometry only spheres
    /// with radius > 0. The end-effector frame is the link named `end_effector`, or the last
    /// arm body if there is none.
    pub fn from_urdf_str(urdf: &str) -> Result<Robot, ModelError> {
        let doc = urdf_rs::read_from_string(urdf).map_err(|e| ModelError::Parse(e.to_string()))?;
        let tree = Tree::of(&doc)?;
        let chain = Chain::walk(&doc, &tree)?;
        let Bodies {
            inertias,
            spheres,
            frames,
        } = Bodies::gather(&doc, &chain.link_body)?;
        for (b, inertia) in inertias.iter().enumerate() {
            if inertia.mass <= 0.0 {
                return Err(ModelError::MasslessBody {
                    link: chain.body_names[b].clone(),
                    mass: inertia.mass,
                });
            }
        }
        let body_names = chain.body_names;
        let ee_frame = frames
            .iter()
            .position(|f| f.name == "end_effector")
            .or_else(|| frames.iter().position(|f| f.name == body_names[NJ]))
            .unwrap_or(0);
        let total_mass = inertias.iter().map(|i| i.mass).sum();
        let joint_names = chain.joints.iter().map(|j| j.name.clone()).collect();
        Ok(Robot {
            name: doc.name.clone(),
            body_names,
            inertias,
            joints: chain.joints,
            joint_names,
            spheres,
            frames,
            ee_frame,
            total_mass,
        })
    }

    /// Robot name from the URDF.
    pub fn name(&self) -> &str {
        &self.name
    }
    /// The same robot with other mass properties of body `k` (0: base, 1..=7: the arm's
    /// links): mass × `mass_scale`, rotational inertia about the CoM × `inertia_scale`,
    /// CoM moved by `com_offset` (body frame) [m]. The plant of a run whose model errs
    /// (`[uncertainty.model]`); `None` for a body that does not exist or a scale that is
    /// not positive and finite.
    pub fn with_body_mass_properties(
        &self,
        k: usize,
        mass_scale: f64,
        inertia_scale: f64,
        com_offset: Vector3<f64>,
    ) -> Option<Robot> {
        let positive = |x: f64| x.is_finite() && x > 0.0;
        if !(positive(mass_scale)
            && positive(inertia_scale)
            && com_offset.iter().all(|x| x.is_finite()))
        {
            return None;
        }
        let body = *self.inertias.get(k)?;
        let mut robot = self.clone();
        robot.inertias[k] = Inertia::from_com(
            body.mass * mass_scale,
            body.com() + com_offset,
            body.i_com() * inertia_scale,
        );
        robot.total_mass = robot.inertias.iter().map(|i| i.mass).sum();
        Some(robot)
    }

    /// Total mass of base + arm (kg).
    pub fn total_mass(&self) -> f64 {
        self.total_mass
    }
    /// Mass of the base body, including links fixed to it (kg).
    pub fn base_mass(&self) -> f64 {
        self.inertias[0].mass
    }
    /// Rotational inertia of the base body about its CoM, base frame (kg m²).
    pub fn base_inertia_com(&self) -> Matrix3<f64> {
        self.inertias[0].i_com()
    }
    /// CoM of the base body in the base frame (m); zero for the delivered URDF.
    pub fn base_com(&self) -> Vector3<f64> {
        self.inertias[0].com()
    }
    /// Spatial inertia of moving body `k` (0 = base) in its own frame.
    pub fn body_inertia(&self, k: usize) -> Option<&Inertia> {
        self.inertias.get(k)
    }
    /// Names of the moving bodies: `[base, link after joint 1, …, link after joint 7]`.
    pub fn body_names(&self) -> &[String; NJ + 1] {
        &self.body_names
    }
    /// Names of the 7 revolute joints in chain order.
    pub fn joint_names(&self) -> &[String] {
        &self.joint_names
    }
    /// URDF limits of joint `i` (0-based).
    pub fn joint_limits(&self, i: usize) -> Option<JointLimits> {
        self.joints.get(i).map(|j| j.limits)
    }
    /// All joint limits as arrays `(lower, upper, velocity, effort)` (rad, rad, rad/s, N m).
    pub fn joint_limit_arrays(&self) -> ([f64; NJ], [f64; NJ], [f64; NJ], [f64; NJ]) {
        let mut out = ([0.0; NJ], [0.0; NJ], [0.0; NJ], [0.0; NJ]);
        for (i, j) in self.joints.iter().enumerate() {
            out.0[i] = j.limits.lower;
            out.1[i] = j.limits.upper;
            out.2[i] = j.limits.velocity;
            out.3[i] = j.limits.effort;
        }
        out
    }
    /// Unit axis of joint `i` (0-based) in its child body frame.
    pub fn joint_axis(&self, i: usize) -> Option<Vector3<f64>> {
        self.joints.get(i).map(|j| j.axis)
    }
    /// All collision spheres, sorted by body (base first, then arm links 1..=7; URDF order
    /// within a body). Centres are in the frame of body `link`.
    pub fn collision_spheres(&self) -> &[CollisionSphere] {
        &self.spheres
    }
    /// Collision spheres on the arm (body ≥ 1).
    pub fn arm_spheres(&self) -> impl Iterator<Item = (usize, &CollisionSphere)> {
        self.spheres.iter().enumerate().filter(|(_, s)| s.link > 0)
    }
    /// The base collision zone `(c_base, R_base)` (base frame, m): the first sphere on the base.
    pub fn base_sphere(&self) -> Option<&CollisionSphere> {
        self.spheres.iter().find(|s| s.link == 0)
    }
    /// All frames (one per URDF link).
    pub fn frames(&self) -> &[Frame] {
        &self.frames
    }
    /// Index of a frame by URDF link name.
    pub fn frame_index(&self, name: &str) -> Option<usize> {
        self.frames.iter().position(|f| f.name == name)
    }
    /// The end-effector frame.
    pub fn ee_frame(&self) -> &Frame {
        &self.frames[self.ee_frame]
    }
}
