//! Compressed sparse rows of affine weights: one subdivision level (`fine = S coarse`), the
//! composed map from control points to limit points, and the fitting matrices; plus a small
//! row accumulator and the conjugate-gradient solver of the fit's p-step.

use glam::DVec3;

/// A sparse matrix in compressed rows.
#[derive(Clone, Debug, Default)]
pub(crate) struct Csr {
    pub offsets: Vec<u32>,
    pub idx: Vec<u32>,
    pub w: Vec<f64>,
    /// Number of columns.
    pub cols: usize,
}

impl Csr {
    /// An empty matrix with `cols` columns and no rows.
    pub fn new(cols: usize) -> Csr {
        Csr {
            offsets: vec![0],
            idx: Vec::new(),
            w: Vec::new(),
            cols,
        }
    }

    /// The identity of size `n`.
    pub fn identity(n: usize) -> Csr {
        Csr {
            offsets: (0..=n as u32).collect(),
            idx: (0..n as u32).collect(),
            w: vec![1.0; n],
            cols: n,
        }
    }

    /// Number of rows.
    #[inline]
    pub fn rows(&self) -> usize {
        self.offsets.len() - 1
    }

    /// Column indices and weights of row `i`.
    #[inline]
    pub fn row(&self, i: usize) -> (&[u32], &[f64]) {
        let (s, e) = (self.offsets[i] as usize, self.offsets[i + 1] as usize);
        (&self.idx[s..e], &self.w[s..e])
    }

    /// Appends a row.
    pub fn push_row(&mut self, row: &Row) {
        for &(i, w) in &row.entries {
            self.idx.push(i);
            self.w.push(w);
        }
        self.offsets.push(self.idx.len() as u32);
    }

    /// `self * x`.
    pub fn apply(&self, x: &[DVec3]) -> Vec<DVec3> {
        (0..self.rows()).map(|i| self.apply_row(i, x)).collect()
    }

    /// Row `i` of `self * x`.
    #[inline]
    pub fn apply_row(&self, i: usize, x: &[DVec3]) -> DVec3 {
        let (idx, w) = self.row(i);
        let mut s = DVec3::ZERO;
        for (&j, &wj) in idx.iter().zip(w) {
            s += x[j as usize] * wj;
        }
        s
    }

    /// `self^T * y` (length `cols`).
    pub fn apply_transpose(&self, y: &[DVec3]) -> Vec<DVec3> {
        let mut out = vec![DVec3::ZERO; self.cols];
        for (i, &yi) in y.iter().enumerate().take(self.rows()) {
            let (idx, w) = self.row(i);
            for (&j, &wj) in idx.iter().zip(w) {
                out[j as usize] += yi * wj;
            }
        }
        out
    }

    /// `self * other` (rows of `self` index rows of `other`).
    pub fn compose(&self, other: &Csr) -> Csr {
        let mut acc = vec![0.0f64; other.cols];
        let mut mark = vec![false; other.cols];
        let mut touched: Vec<u32> = Vec::new();
        let mut out = Csr::new(other.cols);
        out.idx.reserve(self.idx.len() * 4);
        out.w.reserve(self.idx.len() * 4);
        for i in 0..self.rows() {
            let (idx, w) = self.row(i);
            for (&j, &wj) in idx.iter().zip(w) {
                let (oi, ow) = other.row(j as usize);
                for (&k, &wk) in oi.iter().zip(ow) {
                    if !mark[k as usize] {
                        mark[k as usize] = true;
                        touched.push(k);
                    }
                    acc[k as usize] += wj * wk;
                }
            }
            touched.sort_unstable();
            for &k in &touched {
                let v = acc[k as usize];
                if v != 0.0 {
                    out.idx.push(k);
                    out.w.push(v);
                }
                acc[k as usize] = 0.0;
                mark[k as usize] = false;
            }
            touched.clear();
            out.offsets.push(out.idx.len() as u32);
        }
        out
    }

    /// Diagonal of `self^T self` (length `cols`).
    pub fn gram_diagonal(&self) -> Vec<f64> {
        let mut d = vec![0.0; self.cols];
        for (&j, &w) in self.idx.iter().zip(&self.w) {
            d[j as usize] += w * w;
        }
        d
    }
}

/// One row under construction: a short list of (column, weight), merged on insertion.
#[derive(Clone, Debug, Default)]
pub(crate) struct Row {
    pub entries: Vec<(u32, f64)>,
}

impl Row {
    /// Empties the row.
    #[inline]
    pub fn clear(&mut self) {
        self.entries.clear();
    }

    /// Adds `w` to column `i`.
    #[inline]
    pub fn add(&mut self, i: u32, w: f64) {
        if w == 0.0 {
            return;
        }
        for e in &mut self.entries {
            if e.0 == i {
                e.1 += w;
                return;
            }
        }
        self.entries.push((i, w));
    }
}

/// Solves `A x = b` for a symmetric positive definite `A` given as a closure, three right-hand
/// sides at once (one per coordinate, each its own CG with its own step lengths), with a
/// Jacobi preconditioner. Starts from `x`; stops when every coordinate's residual is below
/// `tol` times its right-hand side, or after `max_iter` iterations. Returns the iterations.
pub(crate) fn conjugate_gradient(
    apply: impl Fn(&[DVec3]) -> Vec<DVec3>,
    diag: &[f64],
    b: &[DVec3],
    x: &mut [DVec3],
    tol: f64,
    max_iter: usize,
) -> usize {
    let n = b.len();
    let inv: Vec<f64> = diag
        .iter()
        .map(|&d| {
            if d > 0.0 && d.is_finite() {
                1.0 / d
            } else {
                1.0
            }
        })
        .collect();
    let ax = apply(x);
    let mut r: Vec<DVec3> = (0..n).map(|i| b[i] - ax[i]).collect();
    let mut z: Vec<DVec3> = (0..n).map(|i| r[i] * inv[i]).collect();
    let mut p = z.clone();
    let dot = |a: &[DVec3], b: &[DVec3]| -> DVec3 {
        let mut s = DVec3::ZERO;
        for i in 0..a.len() {
            s += a[i] * b[i];
        }
        s
    };
    let bnorm = dot(b, b);
    let stop = bnorm * (tol * tol);
    let mut rz = dot(&r, &z);
    for it in 0..max_iter {
        let rr = dot(&r, &r);
        if rr.cmple(stop).all() || !rr.is_finite() {
            return it;
        }
        let ap = apply(&p);
        let pap = dot(&p, &ap);
        // Per coordinate: a converged coordinate (pap = 0) takes no step.
        let alpha = DVec3::select(pap.cmpgt(DVec3::ZERO), rz / pap, DVec3::ZERO);
        for i in 0..n {
            x[i] += p[i] * alpha;
            r[i] -= ap[i] * alpha;
            z[i] = r[i] * inv[i];
        }
        let rz_new = dot(&r, &z);
        let beta = DVec3::select(rz.cmpgt(DVec3::ZERO), rz_new / rz, DVec3::ZERO);
        rz = rz_new;
        for i in 0..n {
            p[i] = z[i] + p[i] * beta;
        }
    }
    max_iter
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn compose_matches_sequential_application() {
        let mut a = Csr::new(3);
        let mut r = Row::default();
        r.add(0, 0.5);
        r.add(1, 0.5);
        a.push_row(&r);
        r.clear();
        r.add(2, 1.0);
        a.push_row(&r);
        let mut b = Csr::new(2);
        for (i, w) in [(0u32, 1.0), (1, 0.0)] {
            r.clear();
            r.add(i, w);
            r.add(1, 0.25);
            b.push_row(&r);
        }
        let x = vec![DVec3::X, DVec3::Y, DVec3::Z];
        let direct = b.apply(&a.apply(&x));
        let composed = b.compose(&a).apply(&x);
        for (p, q) in direct.iter().zip(&composed) {
            assert!((*p - *q).length() < 1e-15);
        }
    }

    #[test]
    fn cg_solves_a_small_spd_system() {
        // A = [[4, 1], [1, 3]]
        let apply = |x: &[DVec3]| vec![x[0] * 4.0 + x[1], x[0] + x[1] * 3.0];
        let b = vec![DVec3::new(1.0, 2.0, 0.0), DVec3::new(2.0, 1.0, 0.0)];
        let mut x = vec![DVec3::ZERO; 2];
        conjugate_gradient(apply, &[4.0, 3.0], &b, &mut x, 1e-14, 50);
        let back = apply(&x);
        for i in 0..2 {
            assert!((back[i] - b[i]).length() < 1e-12);
        }
    }
}
