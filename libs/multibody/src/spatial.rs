//! Spatial (6-D) algebra in the style of Featherstone, written for this crate.
//!
//! Conventions (same ordering as Pinocchio, and as the generalized velocity of the servicer):
//! * a motion vector (twist / spatial acceleration) is `[linear; angular]`, where `linear` is
//!   the velocity (m/s) of the material point currently at the frame origin and `angular` the
//!   angular velocity (rad/s), both in the coordinates of that frame;
//! * a force vector (wrench / momentum) is `[force; moment]`, the moment taken about the frame
//!   origin (N, N m);
//! * a [`Transform`] `(rot, trans)` is the placement of a child frame in a parent frame:
//!   `x_parent = rot * x_child + trans`.

use nalgebra::{Matrix3, Matrix6, Vector3, Vector6};

/// Skew-symmetric cross-product matrix: `skew(a) * b = a × b`.
#[inline]
pub fn skew(a: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -a.z, a.y, a.z, 0.0, -a.x, -a.y, a.x, 0.0)
}

/// Rotation by `angle` (rad) about the unit axis `axis` (Rodrigues' formula).
#[inline]
pub fn axis_angle(axis: &Vector3<f64>, angle: f64) -> Matrix3<f64> {
    let (s, c) = angle.sin_cos();
    let k = skew(axis);
    Matrix3::identity() * c + k * s + (axis * axis.transpose()) * (1.0 - c)
}

/// Rotation from URDF roll-pitch-yaw (fixed axes x, then y, then z): `R = Rz(y) Ry(p) Rx(r)`.
pub fn rpy(r: f64, p: f64, y: f64) -> Matrix3<f64> {
    let (sr, cr) = r.sin_cos();
    let (sp, cp) = p.sin_cos();
    let (sy, cy) = y.sin_cos();
    Matrix3::new(
        cy * cp,
        cy * sp * sr - sy * cr,
        cy * sp * cr + sy * sr,
        sy * cp,
        sy * sp * sr + cy * cr,
        sy * sp * cr - cy * sr,
        -sp,
        cp * sr,
        cp * cr,
    )
}

/// Spatial motion vector `[lin; ang]` (m/s, rad/s or m/s², rad/s²).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Motion {
    pub lin: Vector3<f64>,
    pub ang: Vector3<f64>,
}

/// Spatial force vector `[force; moment about the frame origin]` (N, N m), also used for momenta.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Force {
    pub lin: Vector3<f64>,
    pub ang: Vector3<f64>,
}

impl Motion {
    pub const ZERO: Motion = Motion {
        lin: Vector3::new(0.0, 0.0, 0.0),
        ang: Vector3::new(0.0, 0.0, 0.0),
    };
    #[inline]
    pub fn new(lin: Vector3<f64>, ang: Vector3<f64>) -> Self {
        Self { lin, ang }
    }
    #[inline]
    pub fn from_vector6(v: &Vector6<f64>) -> Self {
        Self::new(v.fixed_rows::<3>(0).into(), v.fixed_rows::<3>(3).into())
    }
    #[inline]
    pub fn to_vector6(&self) -> Vector6<f64> {
        Vector6::new(
            self.lin.x, self.lin.y, self.lin.z, self.ang.x, self.ang.y, self.ang.z,
        )
    }
    /// Motion cross product `self × m`.
    #[inline]
    pub fn cross(&self, m: &Motion) -> Motion {
        Motion::new(
            self.ang.cross(&m.lin) + self.lin.cross(&m.ang),
            self.ang.cross(&m.ang),
        )
    }
    /// Dual cross product `self ×* f`.
    #[inline]
    pub fn cross_force(&self, f: &Force) -> Force {
        Force::new(
            self.ang.cross(&f.lin),
            self.ang.cross(&f.ang) + self.lin.cross(&f.lin),
        )
    }
    /// Power `self · f` (W).
    #[inline]
    pub fn dot(&self, f: &Force) -> f64 {
        self.lin.dot(&f.lin) + self.ang.dot(&f.ang)
    }
}

impl std::ops::Add for Motion {
    type Output = Motion;
    #[inline]
    fn add(self, o: Motion) -> Motion {
        Motion::new(self.lin + o.lin, self.ang + o.ang)
    }
}

impl Force {
    pub const ZERO: Force = Force {
        lin: Vector3::new(0.0, 0.0, 0.0),
        ang: Vector3::new(0.0, 0.0, 0.0),
    };
    #[inline]
    pub fn new(lin: Vector3<f64>, ang: Vector3<f64>) -> Self {
        Self { lin, ang }
    }
    #[inline]
    pub fn from_vector6(v: &Vector6<f64>) -> Self {
        Self::new(v.fixed_rows::<3>(0).into(), v.fixed_rows::<3>(3).into())
    }
    #[inline]
    pub fn to_vector6(&self) -> Vector6<f64> {
        Vector6::new(
            self.lin.x, self.lin.y, self.lin.z, self.ang.x, self.ang.y, self.ang.z,
        )
    }
}

impl std::ops::Add for Force {
    type Output = Force;
    #[inline]
    fn add(self, o: Force) -> Force {
        Force::new(self.lin + o.lin, self.ang + o.ang)
    }
}

impl std::ops::Sub for Force {
    type Output = Force;
    #[inline]
    fn sub(self, o: Force) -> Force {
        Force::new(self.lin - o.lin, self.ang - o.ang)
    }
}

/// Rigid placement of a child frame in a parent frame: `x_parent = rot * x_child + trans`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transform {
    pub rot: Matrix3<f64>,
    pub trans: Vector3<f64>,
}

impl Transform {
    pub const IDENTITY: Transform = Transform {
        rot: Matrix3::new(1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0),
        trans: Vector3::new(0.0, 0.0, 0.0),
    };
    #[inline]
    pub fn new(rot: Matrix3<f64>, trans: Vector3<f64>) -> Self {
        Self { rot, trans }
    }
    /// `self ∘ other` (placement of other's child in self's parent).
    #[inline]
    pub fn compose(&self, other: &Transform) -> Transform {
        Transform::new(self.rot * other.rot, self.rot * other.trans + self.trans)
    }
    /// Point given in the child frame, expressed in the parent frame.
    #[inline]
    pub fn act_point(&self, x: &Vector3<f64>) -> Vector3<f64> {
        self.rot * x + self.trans
    }
    /// Motion given in the child frame, expressed in the parent frame.
    #[inline]
    pub fn act_motion(&self, m: &Motion) -> Motion {
        let ang = self.rot * m.ang;
        Motion::new(self.rot * m.lin + self.trans.cross(&ang), ang)
    }
    /// Motion given in the parent frame, expressed in the child frame.
    #[inline]
    pub fn inv_act_motion(&self, m: &Motion) -> Motion {
        let rt = self.rot.transpose();
        Motion::new(rt * (m.lin - self.trans.cross(&m.ang)), rt * m.ang)
    }
    /// Force given in the child frame, expressed in the parent frame.
    #[inline]
    pub fn act_force(&self, f: &Force) -> Force {
        let lin = self.rot * f.lin;
        Force::new(lin, self.rot * f.ang + self.trans.cross(&lin))
    }
}

/// Rigid-body spatial inertia about a frame origin: mass `m` (kg), first moment `h = m c`
/// (kg m, `c` the CoM in that frame) and rotational inertia `i_o` about the frame ORIGIN
/// (kg m²). `I * [v; ω] = [m v + ω × h; i_o ω + h × v]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Inertia {
    pub mass: f64,
    pub h: Vector3<f64>,
    pub i_o: Matrix3<f64>,
}

impl Inertia {
    pub const ZERO: Inertia = Inertia {
        mass: 0.0,
        h: Vector3::new(0.0, 0.0, 0.0),
        i_o: Matrix3::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0),
    };
    /// From mass, CoM `c` and rotational inertia `i_c` about the CoM (all in the same frame).
    pub fn from_com(mass: f64, c: Vector3<f64>, i_c: Matrix3<f64>) -> Self {
        let sc = skew(&c);
        Inertia {
            mass,
            h: c * mass,
            i_o: i_c - sc * sc * mass,
        }
    }
    /// Rotational inertia about the CoM (the inverse of [`Self::from_com`]'s shift).
    pub fn i_com(&self) -> Matrix3<f64> {
        let sc = skew(&self.com());
        self.i_o + sc * sc * self.mass
    }
    /// Centre of mass in this frame (origin if massless).
    pub fn com(&self) -> Vector3<f64> {
        if self.mass > 0.0 {
            self.h / self.mass
        } else {
            Vector3::zeros()
        }
    }
    #[inline]
    pub fn mul_motion(&self, v: &Motion) -> Force {
        Force::new(
            v.lin * self.mass + v.ang.cross(&self.h),
            self.i_o * v.ang + self.h.cross(&v.lin),
        )
    }
    /// This inertia (given in a child frame) expressed in the parent frame of `x`.
    #[inline]
    pub fn transformed(&self, x: &Transform) -> Inertia {
        let rh = x.rot * self.h;
        let p = skew(&x.trans);
        let srh = skew(&rh);
        Inertia {
            mass: self.mass,
            h: rh + x.trans * self.mass,
            i_o: x.rot * self.i_o * x.rot.transpose() - srh * p - p * srh - p * p * self.mass,
        }
    }
    #[inline]
    pub fn add(&self, o: &Inertia) -> Inertia {
        Inertia {
            mass: self.mass + o.mass,
            h: self.h + o.h,
            i_o: self.i_o + o.i_o,
        }
    }
    pub fn to_matrix(&self) -> Matrix6<f64> {
        ArticulatedInertia::from_rigid(self).to_matrix()
    }
}

/// General symmetric 6×6 force-from-motion operator, stored as blocks
/// `[[a, b], [bᵀ, d]]` (`f = a v + b ω`, `n = bᵀ v + d ω`), used for articulated inertias.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ArticulatedInertia {
    pub a: Matrix3<f64>,
    pub b: Matrix3<f64>,
    pub d: Matrix3<f64>,
}

impl ArticulatedInertia {
    #[inline]
    pub fn from_rigid(i: &Inertia) -> Self {
        ArticulatedInertia {
            a: Matrix3::identity() * i.mass,
            b: -skew(&i.h),
            d: i.i_o,
        }
    }
    #[inline]
    pub fn mul_motion(&self, v: &Motion) -> Force {
        Force::new(
            self.a * v.lin + self.b * v.ang,
            self.b.tr_mul(&v.lin) + self.d * v.ang,
        )
    }
    /// `self − u uᵀ / dinv⁻¹` with `u = [ul; ua]`, i.e. subtract `dinv · u uᵀ`.
    #[inline]
    pub fn sub_rank1(&mut self, ul: &Vector3<f64>, ua: &Vector3<f64>, dinv: f64) {
        self.a -= ul * ul.transpose() * dinv;
        self.b -= ul * ua.transpose() * dinv;
        self.d -= ua * ua.transpose() * dinv;
    }
    /// This operator (given in a child frame) expressed in the parent frame of `x`:
    /// `X*ᵀ I X` with `X` the parent→child motion transform.
    #[inline]
    pub fn transformed(&self, x: &Transform) -> ArticulatedInertia {
        let r = &x.rot;
        let ar = r * self.a * r.transpose();
        let br = r * self.b * r.transpose();
        let dr = r * self.d * r.transpose();
        let p = skew(&x.trans);
        let ap = ar * p;
        let pb = p * br;
        ArticulatedInertia {
            a: ar,
            b: br - ap,
            d: dr + pb + pb.transpose() - p * ap,
        }
    }
    #[inline]
    pub fn add_assign(&mut self, o: &ArticulatedInertia) {
        self.a += o.a;
        self.b += o.b;
        self.d += o.d;
    }
    pub fn to_matrix(&self) -> Matrix6<f64> {
        let mut m = Matrix6::zeros();
        m.fixed_view_mut::<3, 3>(0, 0).copy_from(&self.a);
        m.fixed_view_mut::<3, 3>(0, 3).copy_from(&self.b);
        m.fixed_view_mut::<3, 3>(3, 0)
            .copy_from(&self.b.transpose());
        m.fixed_view_mut::<3, 3>(3, 3).copy_from(&self.d);
        m
    }
}
