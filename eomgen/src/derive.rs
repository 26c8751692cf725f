//! Model -> tapes: kinematics, TMT assembly, lowering.

use runtime::joints::{FrameJoints, JointFrame};
use runtime::kernels::{ArmBlocks, ArmInstance, RestContact};
use runtime::links::ArmFrame;
use runtime::{ModelInfo, TapeSet};

use crate::build::{ArmBlock, FrameRows, assembly_system, link_chain, system};
use crate::cas::ExprId;
use crate::cas::{Cas, Hoist, SymKind};
use crate::model::assembly::FrameRef;
use crate::model::{AssemblyShape, Model, ParamLayout, Structure};
use crate::tmt::contact_frames::{PointGroup, contact_frames};
use crate::tmt::{SYMBOLIC_SOLVE_MAX_DOF, System, assemble, solve_accelerations};

/// Derive the kernels of a model's structure.
pub fn derive(model: &Model) -> TapeSet {
    derive_structure(&Structure::of(model))
}

/// The link recursion's layout and kernels of a structure, with the model
/// info that goes with them, and none of the flat kernels: all that a
/// chain of compiled-in link shapes needs to run on linked compiled cells
/// (`runtime::linked::LinkedKernels`), derived in milliseconds at any
/// element count. `None` where the recursion does not give every kernel:
/// assemblies, elements that are no link cell, contact points off the
/// links' arcs.
pub fn derive_links(structure: &Structure) -> Option<(ModelInfo, runtime::links::LinkKernels)> {
    if structure.assembly.is_some() {
        return None;
    }
    let layout = ParamLayout::of(structure);
    let links = link_chain(structure, &layout)?;
    let points = structure.contact_points;
    let elements = links.layout.contact.len() / points.max(1);
    if points > 0 && elements == 0 {
        return None;
    }
    let n = links.layout.dof;
    let info = ModelInfo {
        contact_points: links.layout.contact.len(),
        contact_groups: element_groups(elements, points, 2 * n),
        ..single_arm_info(structure, &layout)
    };
    Some((info, links))
}

/// The model info of a single arm run by its linked kernels alone: no
/// derived parameters, symbolic solve, joints or contact.
fn single_arm_info(structure: &Structure, layout: &ParamLayout) -> ModelInfo {
    ModelInfo {
        hash: structure.hash(),
        coordinates: crate::method::coordinate_names(structure),
        parameters: layout.names(),
        derived: 0,
        accel: false,
        loads: layout.loads(),
        constraints: Vec::new(),
        blocks: Vec::new(),
        contact_points: 0,
        contact_groups: Vec::new(),
        contact_frames: 0,
        copies: Vec::new(),
    }
}

/// The part kernels of a system of parts (a bare eba arm, no contact)
/// and its metadata, without the rest of its tapes: for a layout that
/// links the compiled-in part kernels (`runtime::linked_parts`).
pub fn derive_parts(structure: &Structure) -> Option<(ModelInfo, runtime::parts::PartKernels)> {
    if structure.assembly.is_some() || structure.contact_points > 0 {
        return None;
    }
    let layout = ParamLayout::of(structure);
    let parts = crate::method::eba::part_kernels(structure, &layout)?;
    Some((single_arm_info(structure, &layout), parts))
}

/// Why a single arm runs on neither the link cells nor the parts: its eba
/// segments' reason (which eba's parts do not cover yet), else that some
/// method's elements are no link cells.
pub fn why_not_linked(structure: &Structure) -> String {
    match crate::method::why_not_parts(structure) {
        Some(why) => format!("{why}, which eba's parts do not cover yet"),
        None => "not every one of its methods' elements is a link cell".into(),
    }
}

/// The contact groups of a chain's points: an element's points each, up to
/// `most` groups (the kernel's `dir` selects them), neighbours merged past
/// that.
fn element_groups(elements: usize, points: usize, most: usize) -> Vec<usize> {
    if elements == 0 {
        return Vec::new();
    }
    let per = elements.div_ceil(most.max(1));
    (0..elements)
        .step_by(per)
        .map(|e| points * per.min(elements - e))
        .collect()
}

/// Derive the kernels of a structure. Only the structure and its parameter
/// layout reach the derivation, so no model number can end up in a kernel.
pub fn derive_structure(structure: &Structure) -> TapeSet {
    let layout = ParamLayout::of(structure);
    let mut cas = Cas::new();
    let mut by_arms = None;
    let (sys, phi, rows, blocks) = match &structure.assembly {
        Some(a) => {
            let assembled = assembly_system(&mut cas, a, &layout);
            if arms_have_own_kernels(a) {
                by_arms = Some((a, assembled.arms, assembled.rest, assembled.on_frames));
            }
            // Arms on other arms' frames move with them: one block of M.
            let blocks = match a.tree() {
                true => vec![assembled.blocks.iter().sum()],
                false => assembled.blocks,
            };
            (assembled.sys, assembled.constraints, assembled.rows, blocks)
        }
        None => (
            system(&mut cas, structure, &layout),
            Vec::new(),
            Vec::new(),
            Vec::new(),
        ),
    };
    let eq = assemble(&mut cas, &sys);
    let mut mass_bias = eq.mass_upper.clone();
    mass_bias.extend_from_slice(&eq.bias);
    let inputs = layout.driven().iter().map(|d| layout.index(d.param));
    let mut hoist = Hoist::new(layout.len()).with_inputs(inputs);
    let mass_bias = cas.to_tape_hoisted(&mass_bias, &mut hoist);
    let outputs = cas.to_tape_hoisted(&eq.outputs, &mut hoist);
    let n = eq.bias.len();
    // Chains whose mass + bias the link recursion computes have no `Accel`
    // kernel: the solve runs on the recursion's output.
    // An assembly is many chains and bodies: flat kernels.
    let single = structure.assembly.is_none();
    let links = if single {
        link_chain(structure, &layout)
    } else {
        None
    };
    // Joints need M and h apart (the constrained solve is at run time).
    let accel = n <= SYMBOLIC_SOLVE_MAX_DOF
        && !links.as_ref().is_some_and(|l| l.mass_bias)
        && phi.is_empty()
        && by_arms.is_none();
    let contact = (!sys.samples.is_empty()).then(|| contact_outputs(&mut cas, &sys));
    let accel_tape = if accel {
        // The contact frames ride along (else the points): they share the
        // kinematics' trig with M and h, and a right-hand side that
        // touches nothing needs nothing else. M and h follow, so that the
        // tape gives `MassBias` too (`TapeSet::accel`).
        let s = solve_accelerations(&mut cas, &eq.mass_upper, &eq.bias);
        let points: Vec<ExprId> = match &contact {
            Some(c) if !c.frames.is_empty() => c.frames.clone(),
            _ => sys.samples.iter().flat_map(|s| s.point).collect(),
        };
        let outs: Vec<_> = (s.qdd.into_iter().chain(s.pivots).chain(s.lower))
            .chain(points)
            .chain(eq.mass_upper.iter().chain(&eq.bias).copied())
            .collect();
        cas.to_tape_hoisted(&outs, &mut hoist)
    } else {
        runtime::Tape::default()
    };
    let jvp = cas.to_tape_hoisted(&eq.jvp, &mut hoist);
    let constraints = if phi.is_empty() {
        runtime::Tape::default()
    } else {
        let outs = constraint_outputs(&mut cas, &sys, &phi, &[]);
        cas.to_tape_hoisted(&outs, &mut hoist)
    };
    let (contact, contact_jacobian, contact_jvp, contact_groups, contact_frames) = match &contact {
        None => Default::default(),
        Some(c) => {
            let groups: Vec<usize> = c.groups.iter().map(|g| g.len() / c.width).collect();
            let points: Vec<ExprId> = c.points.iter().chain(&c.frames).copied().collect();
            (
                cas.to_tape_hoisted(&points, &mut hoist),
                c.groups
                    .iter()
                    .map(|g| cas.to_tape_hoisted(g, &mut hoist))
                    .collect(),
                cas.to_tape_hoisted(&c.tangent, &mut hoist),
                groups,
                c.frames.len(),
            )
        }
    };
    let arm_blocks = by_arms.map(|(a, arms, rest, on_frames)| {
        let mut blocks = arm_blocks(&mut cas, a, &arms, &rest, &contact_groups, &mut hoist);
        blocks.joints = frame_joints(&mut cas, &sys, &blocks, on_frames, &mut hoist);
        blocks
    });
    let derived = hoist.finish(&mut cas);
    TapeSet {
        info: ModelInfo {
            hash: structure.hash(),
            coordinates: sys.coords.names.clone(),
            parameters: layout.names(),
            derived: hoist.len(),
            accel,
            loads: layout.loads(),
            constraints: rows,
            blocks,
            contact_points: sys.samples.len(),
            contact_groups,
            contact_frames,
            copies: Vec::new(),
        },
        mass_bias,
        outputs,
        derived,
        accel: accel_tape,
        jvp,
        constraints,
        contact,
        contact_jacobian,
        contact_jvp,
        parts: match links {
            None if single => crate::method::eba::part_kernels(structure, &layout),
            None => None,
            Some(_) => None,
        },
        links,
        arm_blocks,
    }
}

/// Whether an assembly's arms run on kernels of their own
/// (`runtime::arm_blocks`): not an arm on a compliant base (its
/// coordinates move the arm's base, which a single arm's kernels hold
/// still), nor one on another arm's frame or a body (their coordinates move
/// it). An arm's inputs are copied into its slice each time they are
/// written (`ModelInfo::copies`).
fn arms_have_own_kernels(a: &AssemblyShape) -> bool {
    !a.tree() && (a.arms.iter()).all(|(_, st)| !st.base_compliant)
}

/// The rest of an assembly's `MassBias` and `Jvp` (hoisted with its other
/// kernels), and each distinct arm structure derived once as a single arm,
/// with its contact points when the assembly has contact (`groups`: the
/// flat kernels' groups, which the arms' and the rest's must repeat).
fn arm_blocks(
    cas: &mut Cas,
    a: &AssemblyShape,
    arms: &[ArmBlock],
    rest: &System,
    groups: &[usize],
    hoist: &mut Hoist,
) -> ArmBlocks {
    let eq = assemble(cas, rest);
    let mut mass_bias = eq.mass_upper.clone();
    mass_bias.extend_from_slice(&eq.bias);
    let mut kinds: Vec<(Structure, TapeSet)> = Vec::new();
    let contact = !groups.is_empty();
    let instances: Vec<ArmInstance> = a
        .arms
        .iter()
        .zip(arms)
        .map(|((_, st), b)| {
            let st = Structure {
                contact_points: if contact { st.contact_points } else { 0 },
                ..st.clone()
            };
            let layout = ParamLayout::of(&st);
            let kind = match kinds.iter().position(|(s, _)| *s == st) {
                Some(k) => k,
                None => {
                    let tapes = derive_structure(&st);
                    kinds.push((st, tapes));
                    kinds.len() - 1
                }
            };
            ArmInstance {
                kind,
                first: b.first,
                dof: b.dof,
                params: b.params,
                driven: (layout.driven().iter())
                    .map(|d| layout.index(d.param))
                    .collect(),
            }
        })
        .collect();
    let kinds: Vec<TapeSet> = kinds.into_iter().map(|(_, t)| t).collect();
    let rest_contact = contact.then(|| rest_contact(cas, rest, hoist)).filter(|r| {
        // The arms' groups, then the rest's: the flat kernels' order.
        let mut through_arms: Vec<usize> = (instances.iter())
            .flat_map(|i| kinds[i.kind].info.contact_groups.iter().copied())
            .collect();
        through_arms.extend(&r.groups);
        through_arms == groups
    });
    ArmBlocks {
        rest_mass_bias: cas.to_tape_hoisted(&mass_bias, hoist),
        rest_jvp: cas.to_tape_hoisted(&eq.jvp, hoist),
        rest_outputs: cas.to_tape_hoisted(&eq.outputs, hoist),
        kinds,
        arms: instances,
        rest_contact,
        joints: None,
    }
}

/// The joints' rows on the frames they hold (`runtime::joints`), where
/// the assembly has joints and every arm a joint holds runs on link cells:
/// phi, d phi/dq of the coordinates the rows read (the bodies'), gamma,
/// then d phi/dx per frame variable.
fn frame_joints(
    cas: &mut Cas,
    sys: &System,
    blocks: &ArmBlocks,
    on: FrameRows,
    hoist: &mut Hoist,
) -> Option<FrameJoints> {
    let frames: Vec<JointFrame> = (on.frames.iter())
        .map(|&f| match f {
            FrameRef::Tip(arm) => Some(JointFrame {
                arm,
                at: ArmFrame::Tip,
            }),
            FrameRef::SegmentEnd { arm, segment } => Some(JointFrame {
                arm,
                at: ArmFrame::SegmentEnd(segment),
            }),
            _ => None,
        })
        .collect::<Option<_>>()?;
    let on_cells = |f: &JointFrame| blocks.kinds[blocks.arms[f.arm].kind].links.is_some();
    if on.rows.is_empty() || !frames.iter().all(on_cells) {
        return None;
    }
    let mut outs = constraint_outputs(cas, sys, &on.rows, &on.pairs);
    for &row in &on.rows {
        for vars in &on.vars {
            for &x in vars {
                outs.push(cas.diff(row, x));
            }
        }
    }
    Some(FrameJoints {
        frames,
        rows: cas.to_tape_hoisted(&outs, hoist),
    })
}

/// The contact kernels of the points no arm has (the bodies' centres).
fn rest_contact(cas: &mut Cas, rest: &System, hoist: &mut Hoist) -> RestContact {
    let c = contact_outputs(cas, rest);
    assert!(c.frames.is_empty(), "no contact frames off the arms");
    RestContact {
        contact: cas.to_tape_hoisted(&c.points, hoist),
        contact_jacobian: (c.groups.iter())
            .map(|g| cas.to_tape_hoisted(g, hoist))
            .collect(),
        contact_jvp: cas.to_tape_hoisted(&c.tangent, hoist),
        groups: c.groups.iter().map(|g| g.len() / c.width).collect(),
    }
}

/// The `Constraints` kernel's outputs: phi, J = d phi/dq row by row, and
/// gamma = (d/dt J) qd, the time derivative of phi' = J qd at qdd = 0;
/// `more`: the (symbol, rate) pairs of symbols besides the coordinates
/// that phi reads (a held frame's variables, `FrameRows`).
fn constraint_outputs(
    cas: &mut Cas,
    sys: &System,
    phi: &[ExprId],
    more: &[(ExprId, ExprId)],
) -> Vec<ExprId> {
    let mut pairs = sys.coords.rate_pairs();
    pairs.extend(&sys.seeds);
    pairs.extend(more);
    let mut outs = phi.to_vec();
    for &row in phi {
        for &q in &sys.coords.q {
            outs.push(cas.diff(row, q));
        }
    }
    let rate = cas.kinematic_rates(phi, &pairs);
    outs.extend(cas.kinematic_rates(&rate, &pairs));
    outs
}

/// The contact kernels' outputs: the `Contact` kernel's (per point p, then
/// the contact frames), the `ContactJacobian` kernel's in groups (per point
/// p, v = dp/dt, then J = dp/dq row by row) and the `ContactJvp` kernel's
/// (per point dv and dJ along the direction dq, the `Dir` symbols the `Jvp`
/// kernel reads first).
struct ContactOutputs {
    points: Vec<ExprId>,
    /// The contact frames of a serial chain (`tmt::contact_frames`), which
    /// the groups read; empty where the groups start from the base.
    frames: Vec<ExprId>,
    /// Consecutive points that depend on the same coordinates (an arm
    /// element's, a body's), at most 2 n groups: the runtime evaluates the
    /// groups of the points that touch, selected by `dir`.
    groups: Vec<Vec<ExprId>>,
    tangent: Vec<ExprId>,
    /// Outputs per point in a group: 6 + 3 n.
    width: usize,
}

fn contact_outputs(cas: &mut Cas, sys: &System) -> ContactOutputs {
    let mut pairs = sys.coords.rate_pairs();
    pairs.extend(&sys.seeds);
    let names = &sys.coords.names;
    let n = sys.coords.q.len();
    let dq: Vec<(ExprId, ExprId)> = sys
        .coords
        .q
        .iter()
        .enumerate()
        .map(|(i, &q)| {
            let d = cas.symbol(&format!("{}_dir", names[i]), SymKind::Dir(i as u32));
            (q, d)
        })
        .collect();
    let (mut points, mut tangent) = (Vec::new(), Vec::new());
    // (coordinates the point depends on, its p, v and J)
    let mut per_point: Vec<(Vec<bool>, Vec<ExprId>)> = Vec::new();
    for p in sys.samples.iter().map(|s| &s.point) {
        let v = cas.kinematic_rates(p, &pairs);
        let jac: Vec<ExprId> = p
            .iter()
            .flat_map(|&c| sys.coords.q.iter().map(move |&q| (c, q)))
            .map(|(c, q)| cas.diff(c, q))
            .collect();
        let dv = cas.time_derivatives(&v, &dq);
        let djac = cas.time_derivatives(&jac, &dq);
        let depends: Vec<bool> = (0..n)
            .map(|k| (0..3).any(|c| !cas.is_zero(jac[c * n + k])))
            .collect();
        points.extend(p);
        per_point.push((depends, p.iter().chain(&v).chain(&jac).copied().collect()));
        tangent.extend(dv.iter().chain(&djac));
    }
    let mut groups: Vec<(PointGroup, Vec<ExprId>)> = Vec::new();
    for (i, (depends, outs)) in per_point.into_iter().enumerate() {
        match groups.last_mut() {
            Some((g, o)) if g.depends == depends => {
                g.points.end = i + 1;
                o.extend(outs);
            }
            _ => groups.push((
                PointGroup {
                    depends,
                    points: i..i + 1,
                },
                outs,
            )),
        }
    }
    let width = 6 + 3 * n;
    let (heads, flat): (Vec<PointGroup>, Vec<Vec<ExprId>>) = groups.into_iter().unzip();
    if let Some(f) = contact_frames(cas, sys, &heads).filter(|f| f.groups.len() <= 2 * n) {
        return ContactOutputs {
            points,
            frames: f.values,
            groups: f.groups,
            tangent,
            width,
        };
    }
    // `dir` (2 n values) selects the groups: merge neighbours past that.
    let mut groups = flat;
    let per = groups.len().div_ceil((2 * n).max(1));
    if per > 1 {
        groups = groups.chunks(per).map(|c| c.concat()).collect();
    }
    ContactOutputs {
        points,
        frames: Vec::new(),
        groups,
        tangent,
        width,
    }
}
