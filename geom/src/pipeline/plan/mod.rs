//! Phase one of a job: a typed [`JobSpec`] and its meshes become a [`Plan`], everything a
//! method needs and nothing it must look up again. The one resolver: `auto` picks its method,
//! vertex ids of inputs with their own layouts become welded ids ([`input_ids`]), anchors given
//! as points become vertices ([`anchor_points`]), meshes in several parts pair up ([`parts`]),
//! and the options every pair method shares become one [`OutputOptions`]. A plan is only read
//! after this; nothing turns it back into a spec.

pub(crate) mod anchor_points;
mod input_ids;
mod method;
pub(crate) mod parts;
pub mod same_shape;

pub use method::MethodPlan;

use crate::error::Result;
use crate::map::transfer::TransferOptions;
use crate::mesh::{InputLayout, Mesh};
use crate::pipeline::spec::JobSpec;
use crate::pipeline::spec::anchor_spec::id_rows;
use crate::pipeline::spec::auto::AutoChoice;
use crate::pipeline::spec::transfer;
use anchor_points::AnchorSnap;
use parts::PartsPlan;
use std::borrow::Cow;

/// The options every pair method shares, read once from whichever method's options hold them.
#[derive(Debug, Clone)]
pub struct OutputOptions {
    /// Surface samples per direction for the Hausdorff / RMS metrics.
    pub metric_samples: usize,
    /// Source attributes carried onto the target (`target_transferred.glb`).
    pub transfer: TransferOptions,
    /// `morph.glb` also holds the target placed on the source.
    pub inverse_morph: bool,
}

impl OutputOptions {
    fn of(spec: &JobSpec) -> Result<OutputOptions> {
        let (metric_samples, transfer, inverse_morph) = match spec {
            JobSpec::Voronoi(s) | JobSpec::Greedy(s) => {
                (s.options.metric_samples, &s.options.transfer, s.options.inverse_morph)
            }
            JobSpec::Homology(s) => (s.options.metric_samples, &s.options.transfer, s.options.inverse_morph),
            JobSpec::Spherical(s) => (s.options.metric_samples, &s.options.transfer, s.options.inverse_morph),
            JobSpec::Auto(s) => (s.options.metric_samples, &s.options.transfer, s.options.inverse_morph),
            JobSpec::Quad(s) => (s.options.metric_samples, &Vec::new(), false),
        };
        Ok(OutputOptions { metric_samples, transfer: transfer::parse(transfer)?, inverse_morph })
    }

    /// Whether any attribute is carried.
    pub fn wants_transfer(&self) -> bool {
        !self.transfer.texcoords.is_empty() || self.transfer.color || self.transfer.skin
    }
}

/// Everything a job runs on.
pub struct Plan<'a> {
    /// The meshes as read (the outputs in the inputs' own layouts refer to these).
    pub originals: &'a [Mesh],
    /// Each input's own layout (glTF, OBJ with seams), if it has one.
    pub layouts: Vec<Option<&'a InputLayout>>,
    /// The meshes the method runs on: the originals with a vertex inserted at each point anchor
    /// that fell inside a face (after the original vertices).
    pub meshes: Cow<'a, [Mesh]>,
    pub method: MethodPlan,
    pub output: OutputOptions,
    /// For a job that named no method: what ran, and why.
    pub auto: Option<AutoChoice>,
    /// Anchor rows given as points, as resolved.
    pub snaps: Vec<AnchorSnap>,
    /// Meshes in several parts: the part pairs, each with its own method plan.
    pub parts: Option<PartsPlan>,
}

impl<'a> Plan<'a> {
    /// Resolves `spec` on `meshes` (two for pair jobs, source then target); `layouts` may be
    /// shorter than `meshes` (missing = none).
    ///
    /// # Errors
    /// `auto`'s choice failing; `InputError::Anchors` for an id past an input's vertices, a bad
    /// point, a part without anchors; `InputError::Spec` for an unknown attribute to transfer;
    /// `InputError::Invalid` for one the source lacks.
    pub fn new(spec: &JobSpec, meshes: &'a [Mesh], layouts: &'a [Option<InputLayout>]) -> Result<Plan<'a>> {
        let layouts: Vec<Option<&InputLayout>> = layouts.iter().map(Option::as_ref).collect();
        let mut spheres = false;
        let (spec, mut auto) = match spec {
            JobSpec::Auto(a) => {
                let summaries: Vec<_> = meshes.iter().map(crate::topology::summary).collect();
                let closed = |m: &crate::topology::Summary| m.components == 1 && m.boundary_loops == 0 && m.genus == 0;
                spheres = summaries.len() == 2 && summaries.iter().all(closed);
                let (spec, why) = a.resolve(&summaries)?;
                (spec, Some(why))
            }
            _ => (spec.clone(), None),
        };
        let output = OutputOptions::of(&spec)?;
        let mut method = MethodPlan::new(spec)?;
        input_ids::to_welded(&mut method, &layouts)?;
        if let (true, Some(source)) = (output.wants_transfer(), meshes.first()) {
            transfer::check_source(&output.transfer, source, layouts.first().copied().flatten())?;
        }
        let (meshes_run, snaps) = match anchor_points::resolve(&mut method, meshes)? {
            Some((inserted, snaps)) => (Cow::Owned(inserted), snaps),
            None => (Cow::Borrowed(meshes), Vec::new()),
        };
        if spheres && let Some(why) = auto.as_mut() {
            same_shape_or_spherical(&mut method, why, &meshes_run);
        }
        let parts = match method.parts_rows() {
            Some((rows, boundaries)) => parts::plan(&meshes_run, &id_rows(rows)?, boundaries)?,
            None => None,
        };
        Ok(Plan { originals: meshes, layouts, meshes: meshes_run, method, output, auto, snaps, parts })
    }
}

/// `auto` on two closed connected genus-0 meshes picked `voronoi`; when the anchors say the
/// meshes are different shapes ([`same_shape`]), `spherical` runs instead. The reason says
/// which, with the figure.
fn same_shape_or_spherical(method: &mut MethodPlan, why: &mut AutoChoice, meshes: &[Mesh]) {
    use crate::pipeline::spec::{SphericalOptions, SphericalSpec};
    let (MethodPlan::Layout(crate::pipeline::spec::Method::Voronoi, spec), [s, t]) = (&*method, meshes) else {
        return;
    };
    // Anchors the layout refuses: it reports them itself when it runs.
    let Ok(pairs) = spec.validate(crate::pipeline::spec::Method::Voronoi, s, t) else { return };
    let Some(d) = same_shape::anchor_geodesic_difference(s, t, &pairs) else { return };
    if d <= same_shape::DIFFERENT {
        why.reason = format!(
            "{}; the same shape (anchor geodesics differ by a median of {:.1}%, at most {:.0}%)",
            why.reason,
            100.0 * d,
            100.0 * same_shape::DIFFERENT
        );
        return;
    }
    let o = &spec.options;
    *method = MethodPlan::Spherical(SphericalSpec {
        anchors: spec.anchors.clone(),
        options: SphericalOptions {
            metric_samples: o.metric_samples,
            transfer: o.transfer.clone(),
            inverse_morph: o.inverse_morph,
        },
    });
    *why = AutoChoice {
        method: "spherical",
        reason: format!(
            "two closed connected genus-0 meshes of different shapes (anchor geodesics differ by a median of {:.1}%, over {:.0}%)",
            100.0 * d,
            100.0 * same_shape::DIFFERENT
        ),
    };
}
