//! Obstacle shapes and the signed distance of a point from them: the gap
//! and the outward normal at the nearest surface point, written once over
//! any number type (f64, or dual numbers for the exact Jacobian).

use num_dual::DualNum;

/// A vector of three numbers of type T.
pub type V<T> = [T; 3];

/// The shape of an obstacle in its rest pose (world coordinates).
#[derive(Clone, Debug, PartialEq)]
pub enum Shape {
    /// A half space: a point on its surface and the unit outward normal.
    Plane {
        point: [f64; 3],
        normal: [f64; 3],
    },
    Sphere {
        center: [f64; 3],
        radius: f64,
    },
    /// A finite, capped cylinder: unit axis, half length.
    Cylinder {
        center: [f64; 3],
        axis: [f64; 3],
        radius: f64,
        half_length: f64,
    },
    /// A box: its rotation R (columns: the box's axes in the world) and
    /// half sizes along them.
    Box {
        center: [f64; 3],
        rotation: [[f64; 3]; 3],
        half: [f64; 3],
    },
}

fn sub<T: DualNum<Primitive = f64> + Copy>(a: V<T>, b: [f64; 3]) -> V<T> {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot_c<T: DualNum<Primitive = f64> + Copy>(a: V<T>, b: [f64; 3]) -> T {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

pub(crate) fn norm<T: DualNum<Primitive = f64> + Copy>(a: V<T>) -> T {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}

/// A unit vector along `a`, or `fallback` where `a` vanishes (a point at a
/// sphere's centre: any direction is nearest).
pub(crate) fn unit<T: DualNum<Primitive = f64> + Copy>(a: V<T>, fallback: [f64; 3]) -> V<T> {
    let len = norm(a);
    if len.re() <= f64::EPSILON {
        return fallback.map(T::from);
    }
    a.map(|c| c / len)
}

impl Shape {
    /// The signed distance of `p` from the shape (negative inside) and the
    /// outward normal there, with the shape displaced by `offset`.
    pub fn distance<T: DualNum<Primitive = f64> + Copy>(
        &self,
        p: V<T>,
        offset: [f64; 3],
    ) -> (T, V<T>) {
        match self {
            Shape::Plane { point, normal } => {
                let rel = sub(sub(p, *point), offset);
                (dot_c(rel, *normal), normal.map(T::from))
            }
            Shape::Sphere { center, radius } => {
                let rel = sub(sub(p, *center), offset);
                (norm(rel) - *radius, unit(rel, [0.0, 0.0, 1.0]))
            }
            Shape::Cylinder {
                center,
                axis,
                radius,
                half_length,
            } => {
                let rel = sub(sub(p, *center), offset);
                cylinder(rel, *axis, *radius, *half_length)
            }
            Shape::Box {
                center,
                rotation,
                half,
            } => {
                let rel = sub(sub(p, *center), offset);
                let axes = [0, 1, 2].map(|j| [rotation[0][j], rotation[1][j], rotation[2][j]]);
                let local = axes.map(|a| dot_c(rel, a));
                let (d, n_local) = box_local(local, *half);
                let n = [0, 1, 2].map(|i| {
                    n_local[0] * axes[0][i] + n_local[1] * axes[1][i] + n_local[2] * axes[2][i]
                });
                (d, n)
            }
        }
    }
}

/// A capped cylinder about `axis` through the origin.
fn cylinder<T: DualNum<Primitive = f64> + Copy>(
    rel: V<T>,
    axis: [f64; 3],
    radius: f64,
    half: f64,
) -> (T, V<T>) {
    let h = dot_c(rel, axis);
    let radial = [0, 1, 2].map(|i| rel[i] - h * axis[i]);
    let r = norm(radial);
    // A radial direction that is never undefined: any normal to the axis.
    let fallback = perpendicular(axis);
    let out_r = r - radius;
    let out_h = h.abs() - half;
    let along = axis.map(|a| T::from(a) * h.signum());
    let radial_n = unit(radial, fallback);
    match (out_r.re() > 0.0, out_h.re() > 0.0) {
        (true, true) => {
            // Nearest the rim: both excesses.
            let d = (out_r * out_r + out_h * out_h).sqrt();
            let n = [0, 1, 2].map(|i| (radial_n[i] * out_r + along[i] * out_h) / d);
            (d, n)
        }
        (true, false) => (out_r, radial_n),
        (false, true) => (out_h, along),
        // Inside: the nearer face.
        (false, false) if out_r.re() > out_h.re() => (out_r, radial_n),
        (false, false) => (out_h, along),
    }
}

/// A box of half sizes `half` centred at the origin, in its own axes.
fn box_local<T: DualNum<Primitive = f64> + Copy>(p: V<T>, half: [f64; 3]) -> (T, V<T>) {
    let excess = [0, 1, 2].map(|i| p[i].abs() - half[i]);
    let outside: Vec<usize> = (0..3).filter(|&i| excess[i].re() > 0.0).collect();
    let zero = T::from(0.0);
    if outside.is_empty() {
        // Inside: the nearest face, along its axis.
        let i = (0..3)
            .max_by(|&a, &b| excess[a].re().total_cmp(&excess[b].re()))
            .unwrap_or(0);
        let mut n = [zero; 3];
        n[i] = p[i].signum();
        return (excess[i], n);
    }
    let mut v = [zero; 3];
    for &i in &outside {
        v[i] = excess[i] * p[i].signum();
    }
    let d = norm(v);
    (d, v.map(|c| c / d))
}

/// A unit vector normal to the unit vector `a`.
fn perpendicular(a: [f64; 3]) -> [f64; 3] {
    let e = if a[0].abs() < 0.9 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    let c = [
        a[1] * e[2] - a[2] * e[1],
        a[2] * e[0] - a[0] * e[2],
        a[0] * e[1] - a[1] * e[0],
    ];
    let len = (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt();
    c.map(|x| x / len)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Distances against closed forms at points whose nearest surface
    /// point is known, and the normal against central differences of the
    /// distance (it is the distance's gradient outside every shape).
    #[test]
    fn distances_and_normals() {
        let shapes = [
            Shape::Plane {
                point: [0.0, 1.0, 0.0],
                normal: [0.0, 1.0, 0.0],
            },
            Shape::Sphere {
                center: [1.0, 0.0, 0.0],
                radius: 0.5,
            },
            Shape::Cylinder {
                center: [0.0; 3],
                axis: [0.0, 0.0, 1.0],
                radius: 0.5,
                half_length: 1.0,
            },
            Shape::Box {
                center: [0.0; 3],
                rotation: [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]],
                half: [0.2, 0.3, 0.4],
            },
        ];
        let cases: [(usize, [f64; 3], f64); 8] = [
            (0, [3.0, 1.25, -2.0], 0.25),
            (0, [0.0, 0.9, 0.0], -0.1),
            (1, [1.0, 0.0, 2.0], 1.5),
            (2, [2.0, 0.0, 0.0], 1.5),
            (2, [0.0, 0.0, 3.0], 2.0),
            (2, [3.5, 0.0, 5.0], 5.0),
            // The box turned by 90 degrees about z: its 0.3 half size is
            // along world x.
            (3, [1.0, 0.0, 0.0], 0.7),
            (3, [0.0, 0.1, 0.0], -0.1),
        ];
        for (k, p, expected) in cases {
            let (d, n) = shapes[k].distance(p, [0.0; 3]);
            assert!(
                (d - expected).abs() < 1e-14,
                "shape {k} at {p:?}: {d} vs {expected}"
            );
            if d > 0.0 {
                let h = 1e-6;
                for i in 0..3 {
                    let (mut a, mut b) = (p, p);
                    a[i] += h;
                    b[i] -= h;
                    let g = (shapes[k].distance(a, [0.0; 3]).0 - shapes[k].distance(b, [0.0; 3]).0)
                        / (2.0 * h);
                    assert!(
                        (g - n[i]).abs() < 1e-7,
                        "shape {k} normal {i}: {} vs {g}",
                        n[i]
                    );
                }
            }
        }
        // A displaced plane.
        let (d, _): (f64, _) = shapes[0].distance([0.0, 1.0, 0.0], [0.0, -0.5, 0.0]);
        assert!((d - 0.5).abs() < 1e-15);
    }
}
