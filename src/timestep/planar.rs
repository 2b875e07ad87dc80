//! Planar rigid bodies `(x, y, θ)` under gravity, and their contacts: a body-fixed point
//! (a corner) on a plane, a disc on a plane, two discs.
//!
//! # Model
//! Body `b` has coordinates `q_{3b..3b+3} = (x, y, θ)` (centre of mass and angle), mass `m`
//! and moment of inertia `J` about the centre of mass; gravity acts along `−y`:
//! $$ \operatorname{diag}(m, m, J)\,\ddot q_b = (0, -mg, 0). $$
//! A body-fixed point at `r` (body frame) is at `x + R(θ) r`; against a plane through `p₀`
//! with unit normal `n` and tangent `t = (n_y, −n_x)` its gap and rows are
//! $$ g = n\cdot(x + R(\theta) r - p_0),\qquad \nabla g = (n_x, n_y, n\cdot k{\times}R r),
//!    \qquad t\text{-row} = (t_x, t_y, t\cdot k{\times}R r), $$
//! with `k×(a, b) = (−b, a)`. A disc of radius `ρ` on a plane has `g = n·(x − p₀) − ρ`
//! and tangent row `(t_x, t_y, ρ)`; two discs `a`, `b` have `g = |x_b − x_a| − ρ_a − ρ_b`
//! along `n = (x_b − x_a)/|x_b − x_a|` and the tangent row `(−t, ρ_a)` on `a`, `(t, ρ_b)`
//! on `b`.

use crate::Real;
use crate::scalar::to_f64;
use crate::validate::{ParameterError, finite, invertible, non_negative, positive};

use super::error::TimeStepError;
use super::system::{Contact, Geometry, Jacobian, Lagrangian};

/// The inertia of one planar rigid body.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RigidBody<T> {
    mass: T,
    inertia: T,
}

impl<T: Real> RigidBody<T> {
    /// A body of mass `mass` and moment of inertia `inertia` about its centre of mass.
    ///
    /// # Errors
    /// [`ParameterError`] naming the value unless both are finite and > 0 with finite
    /// inverses (the scheme divides by them).
    pub fn new(mass: T, inertia: T) -> Result<Self, ParameterError> {
        Ok(Self {
            mass: invertible("mass", mass)?,
            inertia: invertible("inertia", inertia)?,
        })
    }

    /// A uniform rectangle of width `2·half_width` and height `2·half_height`:
    /// `J = m(w² + h²)/3` for half-sizes `w`, `h`.
    ///
    /// # Errors
    /// [`ParameterError`] unless all are finite and > 0.
    pub fn rectangle(mass: T, half_width: T, half_height: T) -> Result<Self, ParameterError> {
        let (w, h) = (
            positive("half_width", half_width)?,
            positive("half_height", half_height)?,
        );
        let three = T::one() + T::one() + T::one();
        Self::new(mass, mass * (w * w + h * h) / three)
    }

    /// A uniform disc of radius `radius`: `J = m ρ²/2`.
    ///
    /// # Errors
    /// [`ParameterError`] unless both are finite and > 0.
    pub fn disc(mass: T, radius: T) -> Result<Self, ParameterError> {
        let r = positive("radius", radius)?;
        Self::new(mass, mass * r * r / (T::one() + T::one()))
    }

    /// The mass.
    pub fn mass(&self) -> T {
        self.mass
    }

    /// The moment of inertia about the centre of mass.
    pub fn inertia(&self) -> T {
        self.inertia
    }
}

/// A set of planar rigid bodies under gravity `g` along `−y` (a [`Lagrangian`] system with
/// `3 × bodies` coordinates and a constant diagonal mass matrix).
#[derive(Debug, Clone, PartialEq)]
pub struct PlanarBodies<T> {
    bodies: Vec<RigidBody<T>>,
    gravity: T,
}

impl<T: Real> PlanarBodies<T> {
    /// The bodies under gravity `gravity ≥ 0` (m/s², along `−y`).
    ///
    /// # Errors
    /// [`ParameterError`] if `gravity` is negative or not finite, or there is no body.
    pub fn new(bodies: Vec<RigidBody<T>>, gravity: T) -> Result<Self, ParameterError> {
        if bodies.is_empty() {
            return Err(ParameterError::new("bodies", 0.0, "at least one body"));
        }
        Ok(Self {
            bodies,
            gravity: non_negative("gravity", gravity)?,
        })
    }

    /// The bodies.
    pub fn bodies(&self) -> &[RigidBody<T>] {
        &self.bodies
    }

    /// Gravity.
    pub fn gravity(&self) -> T {
        self.gravity
    }

    /// The total linear momentum `(Σ m ẋ, Σ m ẏ)` for velocities `v`.
    pub fn momentum(&self, v: &[T]) -> [T; 2] {
        let mut p = [T::zero(); 2];
        for (b, body) in self.bodies.iter().enumerate() {
            if let (Some(&vx), Some(&vy)) = (v.get(3 * b), v.get(3 * b + 1)) {
                p[0] += body.mass * vx;
                p[1] += body.mass * vy;
            }
        }
        p
    }
}

impl<T: Real> Lagrangian<T> for PlanarBodies<T> {
    fn dofs(&self) -> usize {
        3 * self.bodies.len()
    }
    fn mass(&self, _q: &[T], m: &mut [T]) {
        let n = self.dofs();
        m.iter_mut().for_each(|x| *x = T::zero());
        for (b, body) in self.bodies.iter().enumerate() {
            let i = 3 * b;
            m[i * n + i] = body.mass;
            m[(i + 1) * n + i + 1] = body.mass;
            m[(i + 2) * n + i + 2] = body.inertia;
        }
    }
    fn diagonal_mass(&self) -> bool {
        true
    }
    fn forces(&self, _t: T, _q: &[T], _v: &[T], f: &mut [T]) {
        for (b, body) in self.bodies.iter().enumerate() {
            f[3 * b] = T::zero();
            f[3 * b + 1] = -body.mass * self.gravity;
            f[3 * b + 2] = T::zero();
        }
    }
    fn potential(&self, _t: T, q: &[T]) -> T {
        self.bodies
            .iter()
            .enumerate()
            .fold(T::zero(), |a, (b, body)| {
                a + body.mass * self.gravity * q[3 * b + 1]
            })
    }
}

/// A fixed plane (a line in the plane of motion): a point on it and its unit normal,
/// pointing to the free side.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Plane<T> {
    point: [T; 2],
    normal: [T; 2],
}

impl<T: Real> Plane<T> {
    /// The plane through `point` with normal `normal` (normalized here).
    ///
    /// # Errors
    /// [`ParameterError`] if an entry is not finite or the normal is zero.
    pub fn new(point: [T; 2], normal: [T; 2]) -> Result<Self, ParameterError> {
        for &x in point.iter().chain(normal.iter()) {
            finite("plane", x)?;
        }
        let len = (normal[0] * normal[0] + normal[1] * normal[1]).sqrt();
        if !(len > T::zero() && len.is_finite()) {
            return Err(ParameterError::new(
                "normal",
                to_f64(len),
                "non-zero with a finite length",
            ));
        }
        Ok(Self {
            point,
            normal: [normal[0] / len, normal[1] / len],
        })
    }

    /// The floor `y = height` (normal `+y`).
    ///
    /// # Errors
    /// [`ParameterError`] unless `height` is finite.
    pub fn floor(height: T) -> Result<Self, ParameterError> {
        Self::new([T::zero(), height], [T::zero(), T::one()])
    }

    fn tangent(&self) -> [T; 2] {
        [self.normal[1], -self.normal[0]]
    }

    fn distance(&self, p: [T; 2]) -> T {
        self.normal[0] * (p[0] - self.point[0]) + self.normal[1] * (p[1] - self.point[1])
    }
}

/// What touches what.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Kind<T> {
    Point {
        body: usize,
        local: [T; 2],
        plane: Plane<T>,
    },
    DiscPlane {
        body: usize,
        radius: T,
        plane: Plane<T>,
    },
    DiscDisc {
        a: usize,
        radius_a: T,
        b: usize,
        radius_b: T,
    },
}

/// A contact between planar rigid bodies or with a fixed plane, with its restitution `e`
/// and friction coefficient `μ`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlanarContact<T> {
    kind: Kind<T>,
    e: T,
    mu: T,
}

fn check_laws<T: Real>(e: T, mu: T) -> Result<(), ParameterError> {
    if !(e >= T::zero() && e <= T::one()) {
        return Err(ParameterError::new("e", to_f64(e), "in [0, 1]"));
    }
    non_negative("mu", mu)?;
    Ok(())
}

impl<T: Real> PlanarContact<T> {
    /// A body-fixed point (a corner) at `local` (body frame, from the centre of mass)
    /// against `plane`.
    ///
    /// # Errors
    /// [`ParameterError`] unless `0 ≤ e ≤ 1`, `μ ≥ 0` and `local` is finite.
    pub fn corner_plane(
        body: usize,
        local: [T; 2],
        plane: Plane<T>,
        e: T,
        mu: T,
    ) -> Result<Self, ParameterError> {
        check_laws(e, mu)?;
        finite("local", local[0])?;
        finite("local", local[1])?;
        Ok(Self {
            kind: Kind::Point { body, local, plane },
            e,
            mu,
        })
    }

    /// The centre of mass of `body` (a point mass) against `plane`.
    ///
    /// # Errors
    /// As [`corner_plane`](Self::corner_plane).
    pub fn point_plane(body: usize, plane: Plane<T>, e: T, mu: T) -> Result<Self, ParameterError> {
        Self::corner_plane(body, [T::zero(); 2], plane, e, mu)
    }

    /// A disc of radius `radius` centred on `body`'s centre of mass against `plane`.
    ///
    /// # Errors
    /// [`ParameterError`] unless `radius > 0`, `0 ≤ e ≤ 1`, `μ ≥ 0`.
    pub fn disc_plane(
        body: usize,
        radius: T,
        plane: Plane<T>,
        e: T,
        mu: T,
    ) -> Result<Self, ParameterError> {
        check_laws(e, mu)?;
        Ok(Self {
            kind: Kind::DiscPlane {
                body,
                radius: positive("radius", radius)?,
                plane,
            },
            e,
            mu,
        })
    }

    /// Two discs (spheres in a plane) of radii `radius_a`, `radius_b` on bodies `a ≠ b`.
    ///
    /// # Errors
    /// [`ParameterError`] unless the radii are > 0, `a ≠ b`, `0 ≤ e ≤ 1`, `μ ≥ 0`.
    pub fn disc_disc(
        a: usize,
        radius_a: T,
        b: usize,
        radius_b: T,
        e: T,
        mu: T,
    ) -> Result<Self, ParameterError> {
        check_laws(e, mu)?;
        if a == b {
            return Err(ParameterError::new("b", b as f64, "a body other than a"));
        }
        Ok(Self {
            kind: Kind::DiscDisc {
                a,
                radius_a: positive("radius_a", radius_a)?,
                b,
                radius_b: positive("radius_b", radius_b)?,
            },
            e,
            mu,
        })
    }
}

impl<T: Real> Contact<T> for PlanarContact<T> {
    fn evaluate(&self, _t: T, q: &[T], jac: &mut Jacobian<'_, T>) -> Geometry<T> {
        let at = |i: usize| q.get(i).copied().unwrap_or_else(T::zero);
        match self.kind {
            Kind::Point { body, local, plane } => {
                let i = 3 * body;
                let (s, c) = at(i + 2).sin_cos();
                let d = [c * local[0] - s * local[1], s * local[0] + c * local[1]];
                let kd = [-d[1], d[0]];
                let n = plane.normal;
                let t = plane.tangent();
                jac.normal(i, n[0]);
                jac.normal(i + 1, n[1]);
                jac.normal(i + 2, n[0] * kd[0] + n[1] * kd[1]);
                jac.tangent(i, t[0]);
                jac.tangent(i + 1, t[1]);
                jac.tangent(i + 2, t[0] * kd[0] + t[1] * kd[1]);
                Geometry {
                    gap: plane.distance([at(i) + d[0], at(i + 1) + d[1]]),
                }
            }
            Kind::DiscPlane {
                body,
                radius,
                plane,
            } => {
                let i = 3 * body;
                let n = plane.normal;
                let t = plane.tangent();
                jac.normal(i, n[0]);
                jac.normal(i + 1, n[1]);
                jac.tangent(i, t[0]);
                jac.tangent(i + 1, t[1]);
                jac.tangent(i + 2, radius);
                Geometry {
                    gap: plane.distance([at(i), at(i + 1)]) - radius,
                }
            }
            Kind::DiscDisc {
                a,
                radius_a,
                b,
                radius_b,
            } => {
                let (ia, ib) = (3 * a, 3 * b);
                let dx = at(ib) - at(ia);
                let dy = at(ib + 1) - at(ia + 1);
                let len = (dx * dx + dy * dy).sqrt();
                // Coincident centres: any direction is a normal; take +x.
                let n = if len > T::zero() {
                    [dx / len, dy / len]
                } else {
                    [T::one(), T::zero()]
                };
                let t = [n[1], -n[0]];
                jac.normal(ia, -n[0]);
                jac.normal(ia + 1, -n[1]);
                jac.normal(ib, n[0]);
                jac.normal(ib + 1, n[1]);
                jac.tangent(ia, -t[0]);
                jac.tangent(ia + 1, -t[1]);
                jac.tangent(ia + 2, radius_a);
                jac.tangent(ib, t[0]);
                jac.tangent(ib + 1, t[1]);
                jac.tangent(ib + 2, radius_b);
                Geometry {
                    gap: len - radius_a - radius_b,
                }
            }
        }
    }
    fn restitution(&self) -> T {
        self.e
    }
    fn friction(&self) -> T {
        self.mu
    }
    fn check(&self, dofs: usize) -> Result<(), TimeStepError> {
        let bodies = dofs / 3;
        let check = |b: usize| {
            if b < bodies {
                Ok(())
            } else {
                Err(TimeStepError::Dimension {
                    what: "contact body index",
                    got: b,
                    expected: bodies,
                })
            }
        };
        match self.kind {
            Kind::Point { body, .. } | Kind::DiscPlane { body, .. } => check(body),
            Kind::DiscDisc { a, b, .. } => check(a).and(check(b)),
        }
    }
}
