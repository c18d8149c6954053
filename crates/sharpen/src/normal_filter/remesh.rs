//! The mesh the updating phase edits (sharpening-extras.md A.6): positions, triangles with
//! their filtered normals and input parents, faces per vertex, and the two local operations
//! that remove degenerate faces, edge swap (caps) and edge collapse (needles), each applied
//! only when it keeps the mesh an oriented manifold with the same boundary and folds nothing.

use glam::DVec3;

use super::filter::cross;

/// A needle: longest edge at least this many times the shortest (CGAL's
/// `remove_almost_degenerate_faces` default).
pub(crate) const NEEDLE_RATIO: f64 = 4.0;
/// A cap: an angle of at least 160 degrees (CGAL's default); its cosine.
pub(crate) const CAP_COS: f64 = -0.939_692_620_785_908_4;

pub(crate) struct DynMesh {
    pub pos: Vec<DVec3>,
    pub tris: Vec<[u32; 3]>,
    pub alive: Vec<bool>,
    /// Filtered normal of each face slot (fixed during updating).
    pub target: Vec<DVec3>,
    /// Input face of each slot.
    pub parent: Vec<u32>,
    /// Unit normal of the input face `parent` (no face may turn 90 degrees from it).
    pub parent_normal: Vec<DVec3>,
    /// Alive faces around each vertex.
    pub vf: Vec<Vec<u32>>,
    pub removed: Vec<bool>,
    /// Vertices that may move (and be removed by a collapse).
    pub movable: Vec<bool>,
    /// Vertices that may take part in a swap (selected).
    pub selected: Vec<bool>,
    pub boundary: Vec<bool>,
    /// Smallest accepted `|cross|^2` of a face.
    pub min_area2: f64,
    pub swaps: usize,
    pub collapses: usize,
}

impl DynMesh {
    #[inline]
    pub fn face_cross(&self, f: u32) -> DVec3 {
        let [a, b, c] = self.tris[f as usize];
        cross(
            self.pos[a as usize],
            self.pos[b as usize],
            self.pos[c as usize],
        )
    }

    /// Whether a face of slot `f` with cross product `now` (replacing `was`) is acceptable: not
    /// (almost) flat, not turned by 90 degrees or more from `was` nor from its input face.
    #[inline]
    pub fn acceptable(&self, f: u32, now: DVec3, was: DVec3) -> bool {
        now.length_squared() > self.min_area2
            && now.dot(was) > 0.0
            && now.dot(self.parent_normal[f as usize]) > 0.0
    }

    /// Whether moving `v` to `x` keeps every face around it acceptable.
    pub fn move_ok(&self, v: u32, x: DVec3) -> bool {
        self.vf[v as usize].iter().all(|&f| {
            let t = self.tris[f as usize];
            let p = t.map(|w| if w == v { x } else { self.pos[w as usize] });
            self.acceptable(f, cross(p[0], p[1], p[2]), self.face_cross(f))
        })
    }

    /// The (sorted) neighbours of `v`.
    pub fn neighbours(&self, v: u32) -> Vec<u32> {
        let mut n: Vec<u32> = self.vf[v as usize]
            .iter()
            .flat_map(|&f| self.tris[f as usize])
            .filter(|&w| w != v)
            .collect();
        n.sort_unstable();
        n.dedup();
        n
    }

    /// The alive faces holding both `a` and `b`.
    fn edge_faces(&self, a: u32, b: u32) -> Vec<u32> {
        self.vf[a as usize]
            .iter()
            .copied()
            .filter(|&f| self.tris[f as usize].contains(&b))
            .collect()
    }

    /// For an edge of face `f` from `a` to `b` (in `f`'s order), the third vertex.
    fn third(&self, f: u32, a: u32, b: u32) -> u32 {
        let t = self.tris[f as usize];
        t.into_iter().find(|&w| w != a && w != b).unwrap_or(a)
    }

    /// True when `f` runs from `a` to `b` (rather than `b` to `a`).
    fn runs(&self, f: u32, a: u32, b: u32) -> bool {
        let t = self.tris[f as usize];
        (0..3).any(|k| t[k] == a && t[(k + 1) % 3] == b)
    }

    fn is_boundary_edge(&self, a: u32, b: u32) -> bool {
        self.edge_faces(a, b).len() != 2
    }

    /// Lengths of the edges of `f`, edge `k` running from corner `k` to corner `k + 1`.
    pub fn edge_lengths(&self, f: u32) -> [f64; 3] {
        let t = self.tris[f as usize];
        [0, 1, 2].map(|k| self.pos[t[k] as usize].distance(self.pos[t[(k + 1) % 3] as usize]))
    }

    /// Cosine of the largest angle of a triangle.
    pub fn max_angle_cos(p: [DVec3; 3]) -> f64 {
        let mut m = 1.0f64;
        for k in 0..3 {
            let (u, w) = (p[(k + 1) % 3] - p[k], p[(k + 2) % 3] - p[k]);
            let d = (u.length() * w.length()).max(f64::MIN_POSITIVE);
            m = m.min(u.dot(w) / d);
        }
        m
    }

    fn tri_pos(&self, t: [u32; 3]) -> [DVec3; 3] {
        t.map(|w| self.pos[w as usize])
    }

    /// Removes face `f` from the face lists of its vertices.
    fn unlink(&mut self, f: u32) {
        for w in self.tris[f as usize] {
            let l = &mut self.vf[w as usize];
            if let Some(k) = l.iter().position(|&g| g == f) {
                l.swap_remove(k);
            }
        }
    }

    fn link(&mut self, f: u32) {
        for w in self.tris[f as usize] {
            self.vf[w as usize].push(f);
        }
    }

    /// Removes the degeneracy of face `f` if it has one: a needle collapses its shortest edge,
    /// a cap swaps its longest edge. Returns true when the mesh changed.
    pub fn fix_degenerate(&mut self, f: u32) -> bool {
        if !self.alive[f as usize] {
            return false;
        }
        let t = self.tris[f as usize];
        let l = self.edge_lengths(f);
        let (mut lo, mut hi) = (0, 0);
        for k in 1..3 {
            if l[k] < l[lo] {
                lo = k;
            }
            if l[k] > l[hi] {
                hi = k;
            }
        }
        if l[hi] >= NEEDLE_RATIO * l[lo] {
            return self.collapse(t[lo], t[(lo + 1) % 3]);
        }
        if Self::max_angle_cos(self.tri_pos(t)) <= CAP_COS {
            return self.swap(f, t[hi], t[(hi + 1) % 3]);
        }
        false
    }

    /// Swaps the edge `a b` of face `f1` (running from `a` to `b` in `f1`): faces `(a, b, c)`
    /// and `(b, a, d)` become `(a, d, c)` and `(d, b, c)`.
    pub fn swap(&mut self, f1: u32, a: u32, b: u32) -> bool {
        let faces = self.edge_faces(a, b);
        if faces.len() != 2 {
            return false;
        }
        let f2 = if faces[0] == f1 { faces[1] } else { faces[0] };
        if !self.runs(f1, a, b) || !self.runs(f2, b, a) {
            return false;
        }
        let (c, d) = (self.third(f1, a, b), self.third(f2, b, a));
        if c == d || [a, b, c, d].iter().any(|&w| !self.selected[w as usize]) {
            return false;
        }
        if self.neighbours(c).binary_search(&d).is_ok() {
            return false;
        }
        let (x1, x2) = (self.face_cross(f1), self.face_cross(f2));
        let old_max = Self::max_angle_cos(self.tri_pos(self.tris[f1 as usize]))
            .min(Self::max_angle_cos(self.tri_pos(self.tris[f2 as usize])));
        let new = [[a, d, c], [d, b, c]];
        let mut new_max = 1.0f64;
        let mut choice = [(0u32, DVec3::ZERO, DVec3::ZERO); 2];
        for (g, t) in new.iter().enumerate() {
            let p = self.tri_pos(*t);
            let x = cross(p[0], p[1], p[2]);
            new_max = new_max.min(Self::max_angle_cos(p));
            if x.length_squared() <= self.min_area2 || x.dot(x1) <= 0.0 || x.dot(x2) <= 0.0 {
                return false;
            }
            // The new face takes the filtered normal (and input face) of the old face it agrees
            // with best, provided it does not face against that input face.
            let mut opts = [f1, f2];
            if x.dot(self.target[f2 as usize]) > x.dot(self.target[f1 as usize]) {
                opts.swap(0, 1);
            }
            let Some(&src) = opts
                .iter()
                .find(|&&s| x.dot(self.parent_normal[s as usize]) > 0.0)
            else {
                return false;
            };
            choice[g] = (
                self.parent[src as usize],
                self.parent_normal[src as usize],
                self.target[src as usize],
            );
        }
        // Only a swap that opens the largest angle of the pair (no ping-pong).
        if new_max <= old_max + 1e-9 {
            return false;
        }
        self.unlink(f1);
        self.unlink(f2);
        for (slot, g) in [(f1, 0), (f2, 1)] {
            self.tris[slot as usize] = new[g];
            self.parent[slot as usize] = choice[g].0;
            self.parent_normal[slot as usize] = choice[g].1;
            self.target[slot as usize] = choice[g].2;
            self.link(slot);
        }
        self.swaps += 1;
        true
    }

    /// Collapses the edge `a b`: removes the movable end (onto the other end if only one is
    /// movable, else at the midpoint, keeping the lower index). Refused unless the edge is
    /// interior, its two faces have no boundary edge, the ends share exactly the two opposite
    /// vertices (link condition), and no surviving face around them folds or flattens.
    pub fn collapse(&mut self, a: u32, b: u32) -> bool {
        let (ma, mb) = (self.movable[a as usize], self.movable[b as usize]);
        let (gone, keep, x) = match (ma, mb) {
            (false, false) => return false,
            (true, false) => (a, b, self.pos[b as usize]),
            (false, true) => (b, a, self.pos[a as usize]),
            (true, true) => {
                let mid = (self.pos[a as usize] + self.pos[b as usize]) * 0.5;
                (a.max(b), a.min(b), mid)
            }
        };
        if self.boundary[gone as usize] {
            return false;
        }
        let faces = self.edge_faces(a, b);
        if faces.len() != 2 {
            return false;
        }
        let c = self.third(faces[0], a, b);
        let d = self.third(faces[1], a, b);
        if c == d {
            return false;
        }
        for &(u, w) in &[(a, c), (b, c), (a, d), (b, d)] {
            if self.is_boundary_edge(u, w) {
                return false;
            }
        }
        let (na, nb) = (self.neighbours(a), self.neighbours(b));
        let common: Vec<u32> = na
            .iter()
            .copied()
            .filter(|w| nb.binary_search(w).is_ok())
            .collect();
        if common.len() != 2 || !common.contains(&c) || !common.contains(&d) {
            return false;
        }
        // Every surviving face around a or b, with both ends at x and `gone` renamed `keep`.
        for &v in &[a, b] {
            for &f in &self.vf[v as usize] {
                if faces.contains(&f) {
                    continue;
                }
                let t = self.tris[f as usize];
                let p = t.map(|w| {
                    if w == a || w == b {
                        x
                    } else {
                        self.pos[w as usize]
                    }
                });
                if !self.acceptable(f, cross(p[0], p[1], p[2]), self.face_cross(f)) {
                    return false;
                }
            }
        }
        for &f in &faces {
            self.unlink(f);
            self.alive[f as usize] = false;
        }
        let moved = std::mem::take(&mut self.vf[gone as usize]);
        for &f in &moved {
            for w in self.tris[f as usize].iter_mut() {
                if *w == gone {
                    *w = keep;
                }
            }
        }
        self.vf[keep as usize].extend(moved);
        self.pos[keep as usize] = x;
        self.removed[gone as usize] = true;
        self.movable[gone as usize] = false;
        self.collapses += 1;
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A hexagon fan around vertex 0 (closed by nothing: a disk with boundary).
    fn fan(center: DVec3) -> DynMesh {
        let mut pos = vec![center];
        for k in 0..6 {
            let a = k as f64 * std::f64::consts::PI / 3.0;
            pos.push(DVec3::new(a.cos(), a.sin(), 0.0));
        }
        let tris: Vec<[u32; 3]> = (0..6).map(|k| [0, 1 + k, 1 + (k + 1) % 6]).collect();
        dyn_of(pos, tris)
    }

    fn dyn_of(pos: Vec<DVec3>, tris: Vec<[u32; 3]>) -> DynMesh {
        let nv = pos.len();
        let mut vf = vec![Vec::new(); nv];
        for (f, t) in tris.iter().enumerate() {
            for &v in t {
                vf[v as usize].push(f as u32);
            }
        }
        let nt = tris.len();
        let boundary = (0..nv).map(|v| v != 0).collect();
        DynMesh {
            pos,
            alive: vec![true; nt],
            target: vec![DVec3::Z; nt],
            parent: (0..nt as u32).collect(),
            parent_normal: vec![DVec3::Z; nt],
            tris,
            vf,
            removed: vec![false; nv],
            movable: vec![true; nv],
            selected: vec![true; nv],
            boundary,
            min_area2: 1e-20,
            swaps: 0,
            collapses: 0,
        }
    }

    #[test]
    fn moves_that_fold_are_refused() {
        let m = fan(DVec3::ZERO);
        assert!(m.move_ok(0, DVec3::new(0.3, 0.2, 0.1)));
        assert!(!m.move_ok(0, DVec3::new(1.5, 0.0, 0.0)));
    }

    #[test]
    fn boundary_collapses_are_refused_and_interior_ones_keep_a_manifold() {
        let mut m = fan(DVec3::new(0.01, 0.0, 0.0));
        // Edge 0-1 has a boundary edge in its faces (1-2, 6-1): refused.
        assert!(!m.collapse(0, 1));
        assert_eq!(m.collapses, 0);
    }

    #[test]
    fn a_cap_is_swapped_and_the_swap_is_not_undone() {
        // Two triangles on a quad whose diagonal makes a cap: (0,1,2) with vertex 2 almost on 0-1.
        let pos = vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(2.0, 0.0, 0.0),
            DVec3::new(1.0, 0.05, 0.0),
            DVec3::new(1.0, -1.0, 0.0),
        ];
        let mut m = dyn_of(pos, vec![[0, 2, 1], [0, 1, 3]]);
        m.boundary = vec![true; 4];
        m.parent_normal = vec![-DVec3::Z, -DVec3::Z];
        m.target = m.parent_normal.clone();
        assert!(m.fix_degenerate(0));
        assert_eq!(m.swaps, 1);
        let mut e: Vec<[u32; 3]> = m.tris.clone();
        for t in &mut e {
            t.sort_unstable();
        }
        e.sort_unstable();
        assert_eq!(e, vec![[0, 2, 3], [1, 2, 3]]);
        assert!(!m.fix_degenerate(0) && !m.fix_degenerate(1));
    }
}
