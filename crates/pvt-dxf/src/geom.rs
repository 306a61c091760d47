//! Small 3D geometry: points, vectors and affine transforms (OCS, INSERT, units).
//!
//! Owns the arithmetic every other module shares: the DXF arbitrary-axis algorithm that
//! turns an extrusion direction into an object coordinate system, and affine maps that
//! compose block insertions and unit scales. It must not know any DXF entity or option.

/// A point or vector in world coordinates: X, Y, Z.
pub type P3 = [f64; 3];

/// `a + b`.
pub fn add(a: P3, b: P3) -> P3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// `a - b`.
pub fn sub(a: P3, b: P3) -> P3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// `a * s`.
pub fn scale(a: P3, s: f64) -> P3 {
    [a[0] * s, a[1] * s, a[2] * s]
}

/// Dot product.
pub fn dot(a: P3, b: P3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Cross product.
pub fn cross(a: P3, b: P3) -> P3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// Euclidean length.
pub fn norm(a: P3) -> f64 {
    dot(a, a).sqrt()
}

/// Distance between two points.
pub fn dist(a: P3, b: P3) -> f64 {
    norm(sub(a, b))
}

/// True when every coordinate is finite.
pub fn finite(a: P3) -> bool {
    a.iter().all(|v| v.is_finite())
}

/// Distance from `p` to the segment `a`–`b` (to `a` when the segment has no length).
pub fn dist_to_segment(p: P3, a: P3, b: P3) -> f64 {
    let ab = sub(b, a);
    let len2 = dot(ab, ab);
    if len2 <= 0.0 || !len2.is_finite() {
        return dist(p, a);
    }
    let t = (dot(sub(p, a), ab) / len2).clamp(0.0, 1.0);
    dist(p, add(a, scale(ab, t)))
}

/// An affine map `p ↦ M·p + t`, columns of `M` being the images of the unit axes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Affine {
    /// Images of X, Y and Z unit vectors.
    pub cols: [P3; 3],
    /// Translation.
    pub t: P3,
}

impl Affine {
    /// The identity map.
    pub const IDENTITY: Affine = Affine {
        cols: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        t: [0.0, 0.0, 0.0],
    };

    /// A uniform scale about the origin.
    pub fn scaling(s: f64) -> Affine {
        Affine {
            cols: [[s, 0.0, 0.0], [0.0, s, 0.0], [0.0, 0.0, s]],
            t: [0.0; 3],
        }
    }

    /// Maps a vector (no translation).
    pub fn vector(&self, v: P3) -> P3 {
        let c = &self.cols;
        [
            c[0][0] * v[0] + c[1][0] * v[1] + c[2][0] * v[2],
            c[0][1] * v[0] + c[1][1] * v[1] + c[2][1] * v[2],
            c[0][2] * v[0] + c[1][2] * v[1] + c[2][2] * v[2],
        ]
    }

    /// Maps a point.
    pub fn point(&self, p: P3) -> P3 {
        add(self.vector(p), self.t)
    }

    /// `self ∘ inner`: first `inner`, then `self`.
    pub fn then_after(&self, inner: &Affine) -> Affine {
        Affine {
            cols: [
                self.vector(inner.cols[0]),
                self.vector(inner.cols[1]),
                self.vector(inner.cols[2]),
            ],
            t: self.point(inner.t),
        }
    }

    /// The object coordinate system of an extrusion direction (DXF arbitrary-axis algorithm).
    ///
    /// `None` when the direction is zero or not finite. A direction of exactly +Z gives the
    /// identity; −Z gives the mirror X ↦ −X that mirrored drawings use.
    pub fn ocs(normal: P3) -> Option<Affine> {
        let len = norm(normal);
        if !len.is_finite() || len <= 1e-12 {
            return None;
        }
        let n = scale(normal, 1.0 / len);
        if n == [0.0, 0.0, 1.0] {
            return Some(Affine::IDENTITY);
        }
        let limit = 1.0 / 64.0;
        let ax = if n[0].abs() < limit && n[1].abs() < limit {
            cross([0.0, 1.0, 0.0], n)
        } else {
            cross([0.0, 0.0, 1.0], n)
        };
        let ax = scale(ax, 1.0 / norm(ax));
        let ay = cross(n, ax);
        let ay = scale(ay, 1.0 / norm(ay));
        Some(Affine {
            cols: [ax, ay, n],
            t: [0.0; 3],
        })
    }

    /// Determinant of the linear part (negative for a mirror).
    pub fn det(&self) -> f64 {
        dot(self.cols[0], cross(self.cols[1], self.cols[2]))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn minus_z_ocs_mirrors_x() {
        let m = Affine::ocs([0.0, 0.0, -1.0]).unwrap();
        assert_eq!(m.point([2.0, 3.0, 4.0]), [-2.0, 3.0, -4.0]);
        assert!(m.det() > 0.0, "a rotation about Y, not a reflection in 3D");
    }

    #[test]
    fn tilted_ocs_is_orthonormal_and_keeps_normal() {
        let n = [1.0, 2.0, 3.0];
        let m = Affine::ocs(n).unwrap();
        let z = m.vector([0.0, 0.0, 1.0]);
        let k = norm(n);
        for i in 0..3 {
            assert!((z[i] - n[i] / k).abs() < 1e-15);
        }
        assert!((m.det() - 1.0).abs() < 1e-12);
        assert!(dot(m.cols[0], m.cols[1]).abs() < 1e-15);
        assert!(Affine::ocs([0.0; 3]).is_none());
    }

    #[test]
    fn composition_applies_inner_first() {
        let s = Affine::scaling(2.0);
        let t = Affine {
            t: [1.0, 0.0, 0.0],
            ..Affine::IDENTITY
        };
        assert_eq!(t.then_after(&s).point([1.0, 1.0, 1.0]), [3.0, 2.0, 2.0]);
        assert_eq!(s.then_after(&t).point([1.0, 1.0, 1.0]), [4.0, 2.0, 2.0]);
        assert!((dist_to_segment([0.5, 1.0, 0.0], [0.0; 3], [1.0, 0.0, 0.0]) - 1.0).abs() < 1e-15);
    }
}
