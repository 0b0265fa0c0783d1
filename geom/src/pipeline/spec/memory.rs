//! A job's peak memory, estimated before it runs from its meshes' sizes and its options, so a
//! service can refuse a job that would not fit its budget instead of letting it die
//! half-way. The model is linear in what the job allocates in bulk; its constants are fitted
//! to measured peaks (the resident set of `surfmap map` / `surfmap remesh`; `git show 32d23d1:bench/NOTES.md`)
//! and rounded up, so the estimate errs high.

use crate::pipeline::spec::JobSpec;
use crate::topology::Summary;

/// Fixed cost of any job's process: its mapped executable, thread stacks and two allocator
/// arenas' reservations (the budget caps the address space, not the resident set).
const BASE: u64 = 320 << 20;
/// Bytes per mesh vertex of a pair job at the default options (both meshes, their layouts,
/// charts, factorizations and the maps both ways), per input vertex.
const PER_VERTEX: u64 = 6 << 10;
/// A `homology` job's extra per handle: the canonical-basis searches (with backtracking from
/// genus 2 on) and the side domains the natural-class search keeps (`homology::sides`). Fitted
/// with [`HOMOLOGY_PER_VERTEX_PER_GENUS`] to measured peaks: 3holes (genus 3, 7.2k vertices in
/// all) 808 MiB, genus3 (13.3k) 1059 MiB, cup (genus 2, 20k) 489 MiB, kitten (genus 1, 20k)
/// 127 MiB (`git show 32d23d1:bench/NOTES.md`).
const HOMOLOGY_PER_GENUS: u64 = 160 << 20;
/// A `homology` job's extra bytes per input vertex and handle (refined copies of each mesh in
/// the bases and domains kept).
const HOMOLOGY_PER_VERTEX_PER_GENUS: u64 = 12 << 10;
/// Bytes per layout edge node (positions, graph adjacency, search state).
const PER_EDGE_NODE: u64 = 96;
/// Bytes per metric sample (point, nearest face, distances), per direction.
const PER_SAMPLE: u64 = 160;
/// Bytes per remeshed sample of a `quad` job (position, normal, indices, per model).
const PER_REMESH_SAMPLE: u64 = 256;
/// Bytes per written vertex of an OBJ output (text held in memory before it is stored).
const PER_OUTPUT_VERTEX: u64 = 96;

impl JobSpec {
    /// Estimated peak memory in bytes on meshes with these summaries (an upper estimate).
    pub fn memory_estimate(&self, summaries: &[Summary]) -> u64 {
        let vertices: u64 = summaries.iter().map(|s| s.vertices as u64).sum();
        let edges: u64 = summaries.iter().map(|s| s.edges as u64).sum();
        let pair = |layout: &crate::domain::LayoutOptions, samples: usize| {
            let n = &layout.edge_nodes;
            let per_edge = u64::from(n.min_nodes.max(1)) * u64::from(n.ring_factor.max(1));
            let nodes = edges.saturating_mul(per_edge.min(u64::from(n.max_nodes.max(1))));
            PER_VERTEX
                .saturating_mul(vertices)
                .saturating_add(PER_EDGE_NODE.saturating_mul(nodes))
                .saturating_add(PER_SAMPLE.saturating_mul(2 * samples as u64))
        };
        let bytes = match self {
            JobSpec::Auto(spec) => {
                return spec.resolve(summaries).map_or(0, |(spec, _)| spec.memory_estimate(summaries));
            }
            JobSpec::Voronoi(spec) | JobSpec::Greedy(spec) => pair(&spec.options.layout, spec.options.metric_samples),
            // Two embeddings, their hierarchies and the Newton systems: per vertex, as a layout.
            JobSpec::Spherical(spec) => pair(&Default::default(), spec.options.metric_samples),
            // Cut meshes, subdivided bases and the maps, plus what grows with the handles.
            JobSpec::Homology(spec) => {
                let genus = summaries.iter().map(|s| s.genus.max(0) as u64).max().unwrap_or(0);
                pair(&Default::default(), spec.options.metric_samples)
                    .saturating_add(HOMOLOGY_PER_GENUS.saturating_mul(genus))
                    .saturating_add(HOMOLOGY_PER_VERTEX_PER_GENUS.saturating_mul(genus).saturating_mul(vertices))
            }
            JobSpec::Quad(spec) => {
                let o = &spec.options;
                let models = summaries.len() as u64;
                let genus = summaries.first().map_or(0, |s| s.genus.max(0) as u64);
                let rows = (spec.anchors.len() + o.feature_anchors.len()) as u64;
                let patches = 2 * rows + 8 * genus + 2;
                let side = |level: u32| (1u64 << level.min(16)) + 1;
                let per_patch = side(o.level) * side(o.level);
                let image = o.image_level.unwrap_or(o.level.min(8));
                let per_image = if image == 0 { 0 } else { side(image) * side(image) };
                let samples = patches.saturating_mul(per_patch + per_image);
                let outputs = (o.morph.frames as u64 + o.morph.weights.len() as u64 + 2) * patches * per_patch;
                PER_VERTEX
                    .saturating_mul(vertices)
                    .saturating_add(PER_REMESH_SAMPLE.saturating_mul(samples).saturating_mul(models))
                    .saturating_add(PER_OUTPUT_VERTEX.saturating_mul(outputs))
                    .saturating_add(PER_SAMPLE.saturating_mul(2 * o.metric_samples as u64 * models))
            }
        };
        BASE.saturating_add(bytes)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn closed(vertices: usize, genus: i64) -> Summary {
        let faces = 2 * vertices + 4 * genus as usize - 4;
        Summary {
            vertices,
            faces,
            edges: 3 * faces / 2,
            components: 1,
            boundary_loops: 0,
            euler_characteristic: 2 - 2 * genus,
            genus,
            manifold: true,
            orientable: true,
            bbox: [[0.0; 3], [1.0; 3]],
            bbox_diagonal: 3f64.sqrt(),
            area: 1.0,
            attribute_names: None,
            input_vertices: None,
        }
    }

    /// The homology estimate stays above the peaks measured on the shared meshes (resident
    /// set of `surfmap map`, default job with one anchor; git show 32d23d1:bench/NOTES.md).
    #[test]
    fn homology_estimates_cover_the_measured_peaks() {
        let job = JobSpec::from_json(br#"{"method": "homology", "anchors": [[0, 0]]}"#).expect("a homology job");
        let mib = |v: usize, g: i64| job.memory_estimate(&[closed(v, g), closed(v, g)]) >> 20;
        for (v, g, peak_mib) in [(3596, 3, 808), (6652, 3, 1059), (10000, 2, 489), (10000, 1, 127)] {
            assert!(mib(v, g) >= peak_mib, "{v} vertices, genus {g}: {} MiB against {peak_mib}", mib(v, g));
        }
        assert!(mib(5000, 3) > mib(5000, 1));
    }
}
