//! Bilateral mesh denoising (Fleishman, Drori & Cohen-Or, SIGGRAPH 2003), the optional second
//! step of seed 004's pipeline: each vertex moves along its normal by a bilateral average of
//! its neighbours' heights over its tangent plane, with a spatial Gaussian of width
//! `sigma_c` (the mean edge length) and an influence Gaussian of width `sigma_s` (the standard
//! deviation of the heights in the neighbourhood), over the vertices within `2 sigma_c`
//! reached through at most three rings. Heights across a crease are large and get little
//! weight, so creases survive where a Laplacian would round them.
//!
//! Only the simplification sees the denoised mesh; the fit measures against the input, as the
//! paper does. Not handled: volume loss over many iterations (keep them few, 1 to 5).

use crate::Error;
use glam::DVec3;
use whet_mesh::Mesh;

/// Runs `iterations` passes of bilateral denoising.
pub fn bilateral_denoise(mesh: &Mesh, iterations: u32) -> Result<Mesh, Error> {
    if let Some(v) = mesh.positions.iter().position(|p| !p.is_finite()) {
        return Err(Error::InvalidInput(
            whet_mesh::MeshError::NonFiniteCoordinate { vertex: v as u32 },
        ));
    }
    let nv = mesh.positions.len();
    let mut adj: Vec<Vec<u32>> = vec![Vec::new(); nv];
    for &[a, b] in &mesh.undirected_edges() {
        if (a as usize) < nv && (b as usize) < nv {
            adj[a as usize].push(b);
            adj[b as usize].push(a);
        }
    }
    let mut out = mesh.clone();
    let sigma_c = mesh.mean_edge_length();
    if !(sigma_c > 0.0 && sigma_c.is_finite()) {
        return Ok(out);
    }
    let radius2 = 4.0 * sigma_c * sigma_c;
    let mut mark = vec![u32::MAX; nv];
    let mut hood: Vec<u32> = Vec::new();
    let mut next: Vec<u32> = Vec::new();
    for _ in 0..iterations {
        let normals = out.vertex_normals();
        let pos = out.positions.clone();
        for v in 0..nv {
            let n = normals[v];
            if adj[v].is_empty() || !n.is_finite() || n == DVec3::ZERO {
                continue;
            }
            let p = pos[v];
            // Up to three rings within the radius.
            hood.clear();
            mark[v] = v as u32;
            let mut front = vec![v as u32];
            for _ in 0..3 {
                next.clear();
                for &x in &front {
                    for &y in &adj[x as usize] {
                        if mark[y as usize] != v as u32 {
                            mark[y as usize] = v as u32;
                            if (pos[y as usize] - p).length_squared() <= radius2 {
                                hood.push(y);
                                next.push(y);
                            }
                        }
                    }
                }
                std::mem::swap(&mut front, &mut next);
            }
            if hood.is_empty() {
                continue;
            }
            let heights: Vec<f64> = hood.iter().map(|&y| n.dot(pos[y as usize] - p)).collect();
            let mean = heights.iter().sum::<f64>() / heights.len() as f64;
            let var =
                heights.iter().map(|h| (h - mean) * (h - mean)).sum::<f64>() / heights.len() as f64;
            let sigma_s2 = var.max(1e-4 * sigma_c * sigma_c);
            let (mut sum, mut norm) = (0.0, 0.0);
            for (k, &y) in hood.iter().enumerate() {
                let d2 = (pos[y as usize] - p).length_squared();
                let h = heights[k];
                let w = libm::exp(-d2 / (2.0 * sigma_c * sigma_c))
                    * libm::exp(-h * h / (2.0 * sigma_s2));
                sum += w * h;
                norm += w;
            }
            if norm > 0.0 {
                out.positions[v] = p + n * (sum / norm);
            }
        }
    }
    Ok(out)
}
