//! Three-vectors and 3x3 matrices as plain arrays, and Rodrigues' rotation: all the linear
//! algebra the witness needs, written out so that nothing is shared with `physics/`.

/// A three-vector.
pub type V3 = [f64; 3];
/// A 3x3 matrix, row-major.
pub type M3 = [[f64; 3]; 3];

/// The identity matrix.
pub const IDENTITY: M3 = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

pub fn dot(a: V3, b: V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

pub fn cross(a: V3, b: V3) -> V3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

pub fn add(a: V3, b: V3) -> V3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

pub fn scale(a: V3, k: f64) -> V3 {
    [a[0] * k, a[1] * k, a[2] * k]
}

/// `m * v`.
pub fn mul_v(m: &M3, v: V3) -> V3 {
    [dot(m[0], v), dot(m[1], v), dot(m[2], v)]
}

/// `m^T * v`.
pub fn mul_tv(m: &M3, v: V3) -> V3 {
    let mut out = [0.0; 3];
    for (j, o) in out.iter_mut().enumerate() {
        *o = m[0][j] * v[0] + m[1][j] * v[1] + m[2][j] * v[2];
    }
    out
}

/// `a * b`.
pub fn mul(a: &M3, b: &M3) -> M3 {
    let mut out = [[0.0; 3]; 3];
    for (i, row) in out.iter_mut().enumerate() {
        for (j, c) in row.iter_mut().enumerate() {
            *c = (0..3).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    out
}

/// The right-handed rotation by `th` (rad) about the unit vector `u`:
/// `I + sin(th) [u]x + (1 - cos(th)) [u]x^2`.
pub fn rodrigues(u: V3, th: f64) -> M3 {
    let k = [[0.0, -u[2], u[1]], [u[2], 0.0, -u[0]], [-u[1], u[0], 0.0]];
    let k2 = mul(&k, &k);
    let (s, c) = th.sin_cos();
    let mut out = IDENTITY;
    for i in 0..3 {
        for j in 0..3 {
            out[i][j] += s * k[i][j] + (1.0 - c) * k2[i][j];
        }
    }
    out
}

/// The transpose of `m`.
pub fn transpose(m: &M3) -> M3 {
    std::array::from_fn(|i| std::array::from_fn(|j| m[j][i]))
}
