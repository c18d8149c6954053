//! The normal-filtering sharpener of seed 002 ("Robust mesh sharpening based on normal
//! filtering", JZUS-A 2009), with the formulas restored in
//! `shared/docs/sharpening-extras.md` Part A. Phases, one file each (docs/sharpen.md, "The
//! normal-filtering sharpener"):
//!
//! 0. `denoise` (not in the paper): non-uniform samplings are refused, noisy meshes are denoised
//!    first (Sun et al. 2007's bilateral normal filter and vertex updates);
//! 1. `detect`: feature faces by bounded normal variation (A.1-A.2);
//! 2. `filter`: bilaplacian pre-smoothing of the absolute feature vertices, greedy normal
//!    filtering from the outside of each feature inwards, normal rectifying (A.3-A.5);
//! 3. `update` and `remesh`: least-squares vertex updating with flip avoidance, caps swapped and
//!    needles collapsed (A.6).

mod denoise;
mod detect;
mod filter;
mod remesh;
mod select;
mod update;

pub use select::VertexSelection;

use std::time::Instant;

use glam::DVec3;
use whet_mesh::{CornerId, CornerTable, FaceId, Mesh, MeshError, VertexId};

use crate::options::SharpenOptions;
use crate::report::SharpenReport;
use crate::tags::SharpTags;
use crate::{Error, Sharpened};

pub(crate) const NONE: u32 = u32::MAX;

/// Sharp-edge tags: the faces' filtered normals more than this far apart (cos 30 degrees).
const TAG_COS: f64 = 0.866_025_403_784_438_6;

/// Updating moves no vertex farther than this times `rho` (see `update::update`).
const REACH: f64 = 0.5;

/// Faces may not get smaller than this fraction of `L^2` (as `|cross|^2`, so squared).
const MIN_AREA: f64 = 1e-6;

/// Read-only geometry the detection and filtering floods walk.
pub(crate) struct Geo<'a> {
    pub positions: &'a [DVec3],
    pub tris: &'a [[u32; 3]],
    pub centroids: &'a [DVec3],
    /// Edge neighbours of each face (`NFI`), `NONE` across a boundary edge.
    pub nfi: &'a [[u32; 3]],
}

impl Geo<'_> {
    /// `d(c, f_k)^2` as in A.1: the smallest squared distance from `c` to the corners and the
    /// centroid of `f_k`.
    #[inline]
    pub fn dist2(&self, c: DVec3, k: u32) -> f64 {
        let t = self.tris[k as usize];
        let mut d = c.distance_squared(self.centroids[k as usize]);
        for v in t {
            d = d.min(c.distance_squared(self.positions[v as usize]));
        }
        d
    }
}

fn normals_and_centroids(positions: &[DVec3], tris: &[[u32; 3]]) -> (Vec<DVec3>, Vec<DVec3>) {
    tris.iter()
        .map(|t| {
            let p = t.map(|v| positions[v as usize]);
            (
                filter::cross(p[0], p[1], p[2]).normalize_or_zero(),
                (p[0] + p[1] + p[2]) / 3.0,
            )
        })
        .unzip()
}

/// Runs the normal filter on `mesh`, on the whole mesh or on `selection`.
pub(crate) fn run(
    mesh: &Mesh,
    opts: &SharpenOptions,
    selection: Option<&VertexSelection>,
) -> Result<Sharpened, Error> {
    let start = Instant::now();
    opts.validate()?;
    if let Some(v) = mesh.positions.iter().position(|p| !p.is_finite()) {
        return Err(Error::InvalidInput(MeshError::NonFiniteCoordinate {
            vertex: v as u32,
        }));
    }
    let nv = mesh.positions.len();
    let nt = mesh.triangles.len();
    let mut report = SharpenReport {
        method: opts.method,
        smooth_factor: opts.smooth_factor,
        rho: opts.rho,
        eta: opts.eta,
        lambda: opts.lambda,
        input_vertices: nv,
        input_triangles: nt,
        output_vertices: nv,
        ..SharpenReport::default()
    };
    let selected = match selection {
        Some(s) => s.flags(nv)?,
        None => vec![true; nv],
    };
    if nt == 0 {
        report.time = start.elapsed();
        return Ok(Sharpened {
            mesh: mesh.clone(),
            parents: Vec::new(),
            tags: SharpTags::default(),
            report,
        });
    }
    let table = CornerTable::new(mesh).map_err(Error::InvalidInput)?;
    let tris = &mesh.triangles;
    let (normals, _) = normals_and_centroids(&mesh.positions, tris);
    if let Some(t) = normals.iter().position(|n| *n == DVec3::ZERO) {
        return Err(Error::InvalidInput(MeshError::ZeroAreaTriangle {
            triangle: t as u32,
        }));
    }
    let input_normals = normals;
    let mean_edge = mesh.mean_edge_length();
    if !(mean_edge.is_finite() && mean_edge > 0.0) {
        return Err(Error::InvalidInput(MeshError::ZeroAreaTriangle {
            triangle: 0,
        }));
    }
    let rho = opts.rho * mean_edge;
    let rho2 = rho * rho;
    let min_area2 = (MIN_AREA * mean_edge * mean_edge).powi(2);
    let nfi: Vec<[u32; 3]> = (0..nt)
        .map(|t| {
            [0, 1, 2].map(|k| {
                table
                    .opposite(CornerId((3 * t + k) as u32))
                    .map_or(NONE, |o| o.0 / 3)
            })
        })
        .collect();
    let boundary: Vec<bool> = (0..nv)
        .map(|v| table.is_boundary_vertex(VertexId(v as u32)))
        .collect();

    // Not in the paper: a mesh of a few large faces and strips of needles (rho in mean edge
    // lengths means nothing there, and the cap/needle pass collapses the strips) is refused
    // rather than made worse (docs/sharpen.md, "Noise and non-uniform samplings").
    let coarse = denoise::coarse_share(&mesh.positions, tris, mean_edge);
    if coarse > denoise::COARSE_SHARE {
        return Err(Error::Parameter(format!(
            "--method normal-filter needs a roughly uniform sampling, and this mesh is not one: \
             faces with an edge longer than {} mean edge lengths (L = {mean_edge:.3e}) cover \
             {:.0} % of its surface (at most {:.0} % accepted), so rho (in units of L) and the \
             needle removal would make it worse; remesh it uniformly first (e.g. `whet synth` \
             marching cubes, an isotropic remesher) or use --method extended",
            denoise::COARSE_EDGE,
            100.0 * coarse,
            100.0 * denoise::COARSE_SHARE
        )));
    }

    // 1. Detection (after denoising a noisy mesh).
    let t0 = Instant::now();
    let mut positions = mesh.positions.clone();
    let rings = filter::Rings::new(tris, nv);
    // Not in the paper: a noisy mesh is denoised first, and detection and filtering read the
    // denoised normals.
    let denoised = if denoise::noisy_share(&input_normals, &nfi) > denoise::NOISY_SHARE {
        let movable: Vec<bool> = (0..nv).map(|v| selected[v] && !boundary[v]).collect();
        Some(denoise::denoise(
            &mut positions,
            tris,
            &rings,
            &movable,
            &input_normals,
            min_area2,
        ))
    } else {
        None
    };
    let (mut normals, centroids) = normals_and_centroids(&positions, tris);
    if let Some(d) = &denoised {
        normals.clone_from(&d.normals);
    }
    for (t, n) in normals.iter_mut().enumerate() {
        if *n == DVec3::ZERO {
            *n = input_normals[t];
        }
    }
    let eligible: Vec<bool> = tris
        .iter()
        .map(|t| t.iter().all(|&v| selected[v as usize]))
        .collect();
    let geo = Geo {
        positions: &positions,
        tris,
        centroids: &centroids,
        nfi: &nfi,
    };
    let feature = detect::detect(&geo, &normals, &eligible, rho2, opts.eta, opts.lambda);
    let mut any_face = vec![false; nv];
    let mut all_feature = vec![true; nv];
    for (t, tri) in tris.iter().enumerate() {
        for &v in tri {
            any_face[v as usize] |= feature[t];
            all_feature[v as usize] &= feature[t];
        }
    }
    let used: Vec<bool> = (0..nv)
        .map(|v| table.vertex_corner(VertexId(v as u32)).is_some())
        .collect();
    let vft: Vec<bool> = (0..nv).map(|v| used[v] && any_face[v]).collect();
    let faft: Vec<bool> = (0..nv).map(|v| vft[v] && all_feature[v]).collect();
    report.feature_faces = feature.iter().filter(|&&f| f).count();
    report.feature_vertices = vft.iter().filter(|&&f| f).count();
    report.absolute_feature_vertices = faft.iter().filter(|&&f| f).count();
    report.detection_time = t0.elapsed();

    // 2. Pre-smoothing, filtering, rectifying.
    let t1 = Instant::now();
    let movable: Vec<bool> = (0..nv)
        .map(|v| vft[v] && selected[v] && !boundary[v])
        .collect();
    let smooth: Vec<bool> = (0..nv).map(|v| faft[v] && movable[v]).collect();
    let iterations = (4.0 / opts.rho).ceil().max(0.0) as usize;
    report.presmooth_iterations = iterations;
    filter::presmooth(
        &mut positions,
        tris,
        &rings,
        &smooth,
        iterations,
        min_area2,
        &input_normals,
    );
    let (mut normals, centroids) = normals_and_centroids(&positions, tris);
    if let Some(d) = &denoised {
        normals.clone_from(&d.normals);
    }
    for (t, n) in normals.iter_mut().enumerate() {
        if *n == DVec3::ZERO {
            *n = input_normals[t];
        }
    }
    let geo = Geo {
        positions: &positions,
        tris,
        centroids: &centroids,
        nfi: &nfi,
    };
    let mut in_fft = feature.clone();
    let filtered = filter::filter(&geo, &mut normals, &mut in_fft, rho2, opts.eta, opts.lambda);
    report.filtered_normals = filtered.count;
    report.rectified_normals = filter::rectify(&geo, &mut normals, &filtered.adjusted, opts.eta);
    report.filtering_time = t1.elapsed();

    // 3. Updating.
    let t2 = Instant::now();
    let vf = rings.vertex_faces(nv, tris);
    let mut dm = remesh::DynMesh {
        pos: positions,
        tris: tris.clone(),
        alive: vec![true; nt],
        target: normals,
        parent: (0..nt as u32).collect(),
        parent_normal: input_normals,
        vf,
        removed: vec![false; nv],
        movable: movable.clone(),
        selected,
        boundary,
        min_area2,
        swaps: 0,
        collapses: 0,
    };
    let moving: Vec<u32> = (0..nv as u32).filter(|&v| movable[v as usize]).collect();
    let up = update::update(&mut dm, &moving, mean_edge, REACH * rho);
    report.update_iterations = up.sweeps;
    report.flips_avoided = up.flips_avoided;
    report.swaps = dm.swaps;
    report.collapses = dm.collapses;
    report.collapsed_triangles = 2 * dm.collapses;
    report.updating_time = t2.elapsed();

    // Output: the surviving vertices in input order, the surviving faces in slot order.
    let mut index = vec![NONE; nv];
    let mut out_pos = Vec::with_capacity(nv);
    for v in 0..nv {
        if !dm.removed[v] {
            index[v] = out_pos.len() as u32;
            out_pos.push(dm.pos[v]);
        }
    }
    let mut out_tris = Vec::with_capacity(nt);
    let mut parents = Vec::with_capacity(nt);
    let mut out_target = Vec::with_capacity(nt);
    for f in 0..nt {
        if dm.alive[f] {
            out_tris.push(dm.tris[f].map(|v| index[v as usize]));
            parents.push(FaceId(dm.parent[f]));
            out_target.push(dm.target[f]);
        }
    }
    report.moved_input_vertices = (0..nv)
        .filter(|&v| !dm.removed[v] && dm.pos[v] != mesh.positions[v])
        .count();
    let out = Mesh::new(out_pos, out_tris);
    let out_table = CornerTable::new(&out).map_err(|e| {
        Error::Internal(format!(
            "the normal filter broke the mesh ({e}); please report"
        ))
    })?;
    let tags = tags(&out, &out_table, &out_target);
    report.tagged_vertices = tags.vertices.len();
    report.sharp_edges = tags.edges.len();
    report.output_vertices = out.positions.len();
    report.output_triangles = out.triangles.len();
    report.time = start.elapsed();
    Ok(Sharpened {
        mesh: out,
        parents,
        tags,
        report,
    })
}

/// The edges whose two faces' filtered normals are more than 30 degrees apart, and their ends.
fn tags(mesh: &Mesh, table: &CornerTable, target: &[DVec3]) -> SharpTags {
    let mut edges = Vec::new();
    for c in 0..table.corner_count() {
        let Some(o) = table.opposite(CornerId(c as u32)) else {
            continue;
        };
        let (f, g) = (c / 3, o.index() / 3);
        if f < g && target[f].dot(target[g]) < TAG_COS {
            let t = mesh.triangles[f];
            let (a, b) = (t[(c + 1) % 3], t[(c + 2) % 3]);
            edges.push([VertexId(a.min(b)), VertexId(a.max(b))]);
        }
    }
    edges.sort_unstable();
    edges.dedup();
    let mut vertices: Vec<VertexId> = edges.iter().flatten().copied().collect();
    vertices.sort_unstable();
    vertices.dedup();
    SharpTags { vertices, edges }
}

#[cfg(test)]
mod tests;
