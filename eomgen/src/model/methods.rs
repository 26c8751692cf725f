//! The modelling methods a segment's `method` key names: the registry.
//!
//! One line a method: its variant, its name in model files, and the file
//! and type under `method/` that implement it. The list is data, read
//! twice: here it declares the [`Method`] enum (what a model file holds),
//! and `method/mod.rs` reads it again to declare the files and dispatch to
//! their types. So a model names a method without depending on what the
//! methods do, and a new method is one file plus one line below.

use serde::{Deserialize, Serialize};

/// Calls `$then!` with the registry's lines.
macro_rules! methods {
    ($then:ident) => {
        $then! {
            /// A chain of `elements` rigid links joined by revolute joints.
            Rigid = "rigid" => rigid::Rigid,
            /// Piecewise constant curvature: `elements` arcs, one bending angle each
            /// (planar) or two bending angles, optional twist and stretch (3D).
            Pcc = "pcc" => pcc::Pcc,
            /// Piecewise constant strain (the discrete Cosserat rod): pcc's arcs
            /// with all six strains of the rod, two bendings, twist, extension and
            /// two shears, each constant over an element. 3D only; `twist`,
            /// `extension` and `shear` default to true.
            Pcs = "pcs" => pcs::Pcs,
            /// Variable curvature: one constant-curvature arc per segment, each
            /// segment with its own length, section and material.
            Vc = "vc" => vc::Vc,
            /// Euler-Bernoulli elements with relative states: rigid elements joined
            /// at their midpoints by a rotation (two bending angles and a twist, as
            /// a rotation vector) and an optional stretch. 3D only.
            Ebr = "ebr" => ebr::Ebr,
            /// Euler-Bernoulli elements with absolute states: each element's
            /// position and orientation in the world frame (6 coordinates), the
            /// elements coupled by beam springs (bending, twist, axial, shear).
            /// 3D only; twist and stretch are always present.
            Eba = "eba" => eba::Eba,
            /// Reduced-order model: curvature, twist and stretch as polynomials in
            /// s of degree `order`, the coefficients the coordinates; kinematics,
            /// mass and energies by `quadrature` slices along s. 3D only.
            Rom = "rom" => rom::Rom,
            /// The Cosserat rod, solved as a boundary value problem: statics only.
            Cosserat = "cosserat" => cosserat::Cosserat,
        }
    };
}
pub(crate) use methods;

/// Declares [`Method`] and its names from the registry.
macro_rules! declare {
    ($($(#[$doc:meta])* $variant:ident = $name:literal => $file:ident::$ty:ident,)*) => {
        /// How a segment is modelled. Structural: changing it derives anew.
        #[derive(Clone, Copy, Debug, Deserialize, Serialize, PartialEq, Eq, Hash)]
        pub enum Method {
            $($(#[$doc])* #[serde(rename = $name)] $variant,)*
        }

        impl Method {
            /// Its name in model files and messages.
            pub fn name(self) -> &'static str {
                match self {
                    $(Self::$variant => $name,)*
                }
            }
        }
    };
}

methods!(declare);
