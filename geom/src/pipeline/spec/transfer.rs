//! `options.transfer`'s attribute names: parsed into `map::transfer::TransferOptions` and
//! checked against the source's attributes (its summary's at submission, the mesh's in the
//! plan). The transfer itself is [`crate::pipeline::finish`]'s.

use crate::error::{InputError, Result};
use crate::map::transfer::TransferOptions;
use crate::mesh::{Attributes, InputLayout, Mesh};

/// The attributes a job may carry.
pub const TRANSFERABLE: &str =
    "TEXCOORD_0 .. TEXCOORD_7, COLOR_0, JOINTS_0 and WEIGHTS_0 (skin weights travel together)";

/// Parses attribute names.
///
/// # Errors
/// `InputError::Spec` for an unknown or repeated name.
pub fn parse(names: &[String]) -> Result<TransferOptions> {
    let mut o = TransferOptions::default();
    let mut seen = std::collections::HashSet::new();
    for n in names {
        if !seen.insert(n.as_str()) {
            return Err(InputError::Spec(format!("transfer names {n} twice")).into());
        }
        match n.as_str() {
            "COLOR_0" => o.color = true,
            "JOINTS_0" | "WEIGHTS_0" => o.skin = true,
            t => match t.strip_prefix("TEXCOORD_").and_then(|k| k.parse::<usize>().ok()).filter(|&k| k < 8) {
                Some(k) => o.texcoords.push(k),
                None => {
                    return Err(InputError::Spec(format!(
                        "transfer: unknown attribute {n:?}; allowed: {TRANSFERABLE}"
                    ))
                    .into());
                }
            },
        }
    }
    Ok(o)
}

fn source_attributes(source: &Mesh, layout: Option<&InputLayout>) -> Attributes {
    layout.map_or_else(|| Attributes::from(source.attributes()), |l| l.attributes.clone())
}

/// The attribute names of a read mesh (its input layout's when it has one), as the server
/// records them in the mesh's summary.
pub fn attribute_names(mesh: &Mesh, layout: Option<&InputLayout>) -> Vec<String> {
    source_attributes(mesh, layout).names()
}

/// Checks the source has every attribute asked for.
///
/// # Errors
/// `InputError::Invalid` naming the missing attribute and those the source has.
pub fn check_source(o: &TransferOptions, source: &Mesh, layout: Option<&InputLayout>) -> Result<()> {
    check_names(o, &attribute_names(source, layout))
}

/// [`check_source`] on the source's attribute names (a summary's, before the job runs).
///
/// # Errors
/// As [`check_source`].
pub fn check_names(o: &TransferOptions, names: &[String]) -> Result<()> {
    let has = |n: &str| names.iter().any(|x| x == n);
    let missing = o
        .texcoords
        .iter()
        .find(|&&k| !has(&format!("TEXCOORD_{k}")))
        .map(|k| format!("TEXCOORD_{k}"))
        .or_else(|| (o.color && !has("COLOR_0")).then(|| "COLOR_0".to_string()))
        .or_else(|| (o.skin && !(has("JOINTS_0") && has("WEIGHTS_0"))).then(|| "JOINTS_0/WEIGHTS_0".to_string()));
    match missing {
        Some(m) => Err(InputError::Invalid(format!(
            "transfer: the source has no {m} (it has: {})",
            if names.is_empty() { "no attributes".to_string() } else { names.join(", ") }
        ))
        .into()),
        None => Ok(()),
    }
}
