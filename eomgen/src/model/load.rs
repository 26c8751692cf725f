//! `[[load]]`: a force and moment at a point along a segment, or a force
//! per unit length over a whole segment; constant or driven by inputs, in
//! the world frame or turning with the section.

use serde::{Deserialize, Serialize};

/// One declared load.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Load {
    /// The segment it acts on.
    pub segment: usize,
    /// Arc length along the segment (m) of a point load; absent: `force`
    /// is per unit length (N/m) over the whole segment.
    #[serde(default)]
    pub s: Option<f64>,
    /// Force (N, or N/m when distributed).
    #[serde(default)]
    pub force: Option<[f64; 3]>,
    /// Moment (N m), point loads only.
    #[serde(default)]
    pub moment: Option<[f64; 3]>,
    /// Input channels driving the force's components (structural).
    #[serde(default)]
    pub force_inputs: Option<[String; 3]>,
    /// Input channels driving the moment's components (structural).
    #[serde(default)]
    pub moment_inputs: Option<[String; 3]>,
    /// "world" (default) or "local": the section's frame, turning with it
    /// (a follower load). Structural.
    #[serde(default)]
    pub frame: Option<LoadFrame>,
}

/// The frame a load is given in.
#[derive(Clone, Copy, Debug, Deserialize, Serialize, PartialEq, Eq, Hash)]
#[serde(rename_all = "lowercase")]
pub enum LoadFrame {
    World,
    Local,
}

impl Load {
    pub fn has_force(&self) -> bool {
        self.force.is_some() || self.force_inputs.is_some()
    }

    pub fn has_moment(&self) -> bool {
        self.moment.is_some() || self.moment_inputs.is_some()
    }

    pub fn local(&self) -> bool {
        self.frame == Some(LoadFrame::Local)
    }
}

/// Where a load acts in the structure: element `element` of the arm (its
/// quadrature slice for rom) at the fraction `fraction` of it (a point
/// load), or every element of `segment` at its middle (distributed).
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct LoadShape {
    pub segment: usize,
    /// The element and the fraction along it, as f64 bits (structural: the
    /// point's kinematics are derived there); None: distributed.
    pub at: Option<(usize, u64)>,
    pub local: bool,
    pub force: bool,
    pub moment: bool,
    pub force_driven: bool,
    pub moment_driven: bool,
}

impl LoadShape {
    /// The element and the fraction along it of arc length `s` on a
    /// segment of `elements` elements of length `length / elements`, its
    /// first element `first`: a point on a boundary belongs to the element
    /// that ends there.
    pub fn place(s: f64, length: f64, elements: usize, first: usize) -> (usize, f64) {
        let x = (s / length * elements as f64).clamp(0.0, elements as f64);
        let e = (x.ceil() as usize).clamp(1, elements) - 1;
        (first + e, x - e as f64)
    }
}
