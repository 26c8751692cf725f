//! The obstacles' signed distances and the broad phase, over any number
//! type (f64, or dual numbers for the exact Jacobian of the contact
//! forces): the simulation's side of `runtime_kernels::obstacle`, which
//! holds each shape's keys and checks. A shape's distance is written here
//! once, in `Distance for Shape`.
use num_dual::DualNum;
use runtime_kernels::obstacle::Shape;

/// A vector of three numbers of type T.
pub type V<T> = [T; 3];

/// What contact asks of an obstacle's shape.
pub trait Distance {
    /// The signed distance of `p` from the shape (negative inside) and the
    /// outward normal there, with the shape displaced by `offset`.
    fn distance<T: DualNum<Primitive = f64> + Copy>(&self, p: V<T>, offset: [f64; 3]) -> (T, V<T>);
    /// Whether no point of an element can touch the shape displaced by
    /// `offset` within `margin`: the element's points lie in the ellipsoid
    /// of foci `a`, `b` and major axis `length`.
    fn clears(&self, offset: [f64; 3], a: [f64; 3], b: [f64; 3], length: f64, margin: f64) -> bool;
}

fn sub<T: DualNum<Primitive = f64> + Copy>(a: V<T>, b: [f64; 3]) -> V<T> {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot_c<T: DualNum<Primitive = f64> + Copy>(a: V<T>, b: [f64; 3]) -> T {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

pub fn norm<T: DualNum<Primitive = f64> + Copy>(a: V<T>) -> T {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}

/// A unit vector along `a`, or `fallback` where `a` vanishes (a point at a
/// sphere's centre: any direction is nearest).
pub fn unit<T: DualNum<Primitive = f64> + Copy>(a: V<T>, fallback: [f64; 3]) -> V<T> {
    let len = norm(a);
    if len.re() <= f64::EPSILON {
        return fallback.map(T::from);
    }
    a.map(|c| c / len)
}

impl Distance for Shape {
    fn distance<T: DualNum<Primitive = f64> + Copy>(&self, p: V<T>, offset: [f64; 3]) -> (T, V<T>) {
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

    /// Whether every point of the ellipsoid of foci `a` and `b` and major
    /// axis `length` (every point of a curve of that length from a to b)
    /// is farther than `margin` from the shape displaced by `offset`: the
    /// broad phase of the contact frames. A plane by the ellipsoid's
    /// support, min n.x = n.m - sqrt(l^2/4 - |d|^2/4 + (n.d)^2/4) (m the
    /// centre, d = b - a); the others by the sphere about m of radius
    /// l/2 and the signed distance, which moves no faster than the point.
    fn clears(&self, offset: [f64; 3], a: [f64; 3], b: [f64; 3], length: f64, margin: f64) -> bool {
        let m = [0, 1, 2].map(|i| 0.5 * (a[i] + b[i]));
        let half = 0.5 * length.abs();
        match self {
            Shape::Plane { point, normal } => {
                let level = dot(*normal, *point) + dot(*normal, offset);
                plane_clears(*normal, level, a, b, length, margin)
            }
            _ => self.distance(m, offset).0 - half > margin,
        }
    }
}

/// `Shape::clears` for the plane n.x = level: the sphere first (most
/// elements are far), then the ellipsoid, squared (no root).
#[inline]
pub fn plane_clears(
    normal: [f64; 3],
    level: f64,
    a: [f64; 3],
    b: [f64; 3],
    length: f64,
    margin: f64,
) -> bool {
    let (na, nb) = (dot(normal, a), dot(normal, b));
    let half = 0.5 * length.abs();
    let clear = 0.5 * (na + nb) - level - margin;
    if clear > half {
        return true;
    }
    if clear <= 0.0 {
        return false;
    }
    let d = [0, 1, 2].map(|i| b[i] - a[i]);
    let nd = nb - na;
    clear * clear > half * half - 0.25 * dot(d, d) + 0.25 * nd * nd
}

pub fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
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

    /// `clears` may say an ellipsoid (foci a and b, major axis l: every
    /// point x with |x - a| + |x - b| <= l) clears a shape by a margin only
    /// when every point of it does: checked at points on its surface (the
    /// nearest to any shape are there), by bisection along random rays from
    /// its centre. And it is not vacuous: it clears many.
    #[test]
    fn clears_only_what_cannot_touch() {
        let mut state = 0x9e37_79b9_7f4a_7c15_u64;
        let mut uniform = |lo: f64, hi: f64| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            lo + (hi - lo) * (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let dist = |x: [f64; 3], y: [f64; 3]| {
            ((x[0] - y[0]).powi(2) + (x[1] - y[1]).powi(2) + (x[2] - y[2]).powi(2)).sqrt()
        };
        let shapes = [
            Shape::Plane {
                point: [0.0, 0.0, 0.0],
                normal: [0.6, 0.0, 0.8],
            },
            Shape::Sphere {
                center: [0.0; 3],
                radius: 0.3,
            },
            Shape::Cylinder {
                center: [0.0; 3],
                axis: [0.0, 0.6, 0.8],
                radius: 0.2,
                half_length: 0.4,
            },
            Shape::Box {
                center: [0.0; 3],
                rotation: [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]],
                half: [0.2, 0.3, 0.1],
            },
        ];
        for shape in &shapes {
            let mut cleared = 0;
            for _ in 0..2000 {
                let a = [0, 1, 2].map(|_| uniform(-1.0, 1.0));
                let chord = [0, 1, 2].map(|_| uniform(-0.2, 0.2));
                let b = [0, 1, 2].map(|i| a[i] + chord[i]);
                let l = dist(a, b) * uniform(1.0, 4.0) + uniform(0.0, 0.1);
                let margin = uniform(0.0, 0.05);
                let offset = [0, 1, 2].map(|_| uniform(-0.1, 0.1));
                if !shape.clears(offset, a, b, l, margin) {
                    continue;
                }
                cleared += 1;
                let m = [0, 1, 2].map(|i| 0.5 * (a[i] + b[i]));
                for _ in 0..50 {
                    let u = [0, 1, 2].map(|_| uniform(-1.0, 1.0));
                    let len = dist(u, [0.0; 3]).max(1e-6);
                    let u = u.map(|c| c / len);
                    let at = |t: f64| [0, 1, 2].map(|i| m[i] + t * u[i]);
                    let (mut lo, mut hi) = (0.0, l);
                    for _ in 0..60 {
                        let mid = 0.5 * (lo + hi);
                        let x = at(mid);
                        if dist(x, a) + dist(x, b) <= l {
                            lo = mid;
                        } else {
                            hi = mid;
                        }
                    }
                    let x = at(lo);
                    let d: f64 = shape.distance(x, offset).0;
                    assert!(
                        d > margin - 1e-12,
                        "{shape:?}: a point of a cleared ellipsoid is {d} from it (margin {margin})"
                    );
                }
            }
            assert!(cleared > 200, "{shape:?}: {cleared} of 2000 cleared");
        }
    }
}
