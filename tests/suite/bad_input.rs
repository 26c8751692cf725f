//! Bad input gets a clear error: the file, the key path, what is wrong and
//! what is allowed; a non-zero exit; never a panic.

use crate::common::*;

const GOOD: &str = r#"
name = "t"
gravity = [0.0, -9.81, 0.0]
[base]
direction = [0.0, -1.0, 0.0]
[[segment]]
method = "rigid"
length = 0.3
elements = 2
mass = 0.5
joint_stiffness = 1.0
joint_damping = 0.1
[tip]
mass = 0.1
force = [0.0, 0.0, 0.0]
"#;

/// Two rigid arms from walls 0.45 m apart holding a ball between their
/// tips, started bent.
const HELD: &str = r#"
name = "held"
gravity = [0.0, -9.81, 0.0]
[simulate]
t_end = 0.1
q0 = { "left.theta_0_0" = -0.3, "left.theta_0_1" = 0.6, "right.theta_0_0" = 0.3, "right.theta_0_1" = -0.6 }
[[arm]]
name = "left"
base = { position = [0.0, 0.0, 0.0], direction = [1.0, 0.0, 0.0] }
[[arm.segment]]
method = "rigid"
length = 0.2
elements = 2
mass = 0.2
joint_stiffness = 1.0
[[arm]]
name = "right"
base = { position = [0.45, 0.0, 0.0], direction = [-1.0, 0.0, 0.0] }
[[arm.segment]]
method = "rigid"
length = 0.2
elements = 2
mass = 0.2
joint_stiffness = 1.0
[[body]]
name = "ball"
shape = "sphere"
radius = 0.05
mass = 0.1
position = [0.225, -0.05, 0.0]
[[joint]]
name = "left_grip"
kind = "weld"
a = "left.tip"
b = "ball"
offset_b = [-0.05, 0.0, 0.0]
[[joint]]
name = "right_grip"
kind = "pin"
a = "right.tip"
b = "ball"
offset_b = [0.05, 0.0, 0.0]
"#;

/// Assembly errors found when the model is read.
fn assembly_cases() -> Vec<(&'static str, String, Vec<&'static str>)> {
    let r = |a: &str, b: &str| {
        assert!(HELD.contains(a), "{a}");
        HELD.replacen(a, b, 1)
    };
    vec![
        (
            "joint names an unknown arm",
            r("a = \"left.tip\"", "a = \"middle.tip\""),
            vec![
                "joint.left_grip.a",
                "no frame \"middle.tip\"",
                "left.tip",
                "ball",
            ],
        ),
        (
            "joint names an unknown body",
            r("b = \"ball\"", "b = \"bal\""),
            vec!["joint.left_grip.b", "no frame \"bal\""],
        ),
        (
            "joint between a frame and itself",
            r("b = \"ball\"", "b = \"left.tip\""),
            vec!["joint.left_grip.b", "to itself"],
        ),
        (
            "zero body mass",
            r("mass = 0.1", "mass = 0.0"),
            vec!["body.ball.mass", "must be positive"],
        ),
        (
            "negative body mass",
            r("mass = 0.1", "mass = -1.0"),
            vec!["body.ball.mass", "must be positive"],
        ),
        (
            "non-positive inertia",
            r("mass = 0.1", "mass = 0.1\ninertia = -0.001"),
            vec!["body.ball.inertia", "positive-definite"],
        ),
        (
            "duplicate arm names",
            r("name = \"right\"", "name = \"left\""),
            vec!["arm.left.name", "duplicate name"],
        ),
        (
            "a body named as an arm",
            r("name = \"ball\"", "name = \"left\""),
            vec!["body.left.name", "duplicate name"],
        ),
        (
            "duplicate joint names",
            r("name = \"right_grip\"", "name = \"left_grip\""),
            vec!["joint.left_grip.name", "duplicate joint name"],
        ),
        (
            "negative base stiffness",
            r(
                "base = { position = [0.0, 0.0, 0.0], direction = [1.0, 0.0, 0.0] }",
                "base = { position = [0.0, 0.0, 0.0], direction = [1.0, 0.0, 0.0], mass = 1.0, stiffness = -5.0 }",
            ),
            vec!["arm.left.base.stiffness", "must be zero or positive"],
        ),
        (
            "negative rotational stiffness of a compliant base",
            r(
                "base = { position = [0.0, 0.0, 0.0], direction = [1.0, 0.0, 0.0] }",
                "base = { position = [0.0, 0.0, 0.0], direction = [1.0, 0.0, 0.0], mass = 1.0, stiffness = 5.0, rotational_stiffness = -2.0 }",
            ),
            vec![
                "arm.left.base.rotational_stiffness",
                "must be zero or positive",
            ],
        ),
        (
            "a turning compliant base without rotary inertia",
            r(
                "base = { position = [0.0, 0.0, 0.0], direction = [1.0, 0.0, 0.0] }",
                "base = { position = [0.0, 0.0, 0.0], direction = [1.0, 0.0, 0.0], mass = 1.0, stiffness = 5.0, rotational_stiffness = 2.0, inertia = 0.0 }",
            ),
            vec!["arm.left.base.inertia", "needs its rotary inertia"],
        ),
        (
            "an arm's own error under its name",
            r("length = 0.2", "length = -0.2"),
            vec!["arm.left.segment[0].length", "must be positive"],
        ),
        (
            "a 3D body with an impossible inertia",
            r(
                "gravity = [0.0, -9.81, 0.0]",
                "dimensions = 3\ngravity = [0.0, -9.81, 0.0]",
            )
            .replacen(
                "mass = 0.1",
                "mass = 0.1\nprincipal_inertia = [1.0, 0.1, 0.1]",
                1,
            ),
            vec!["body.ball.principal_inertia", "each at most the sum"],
        ),
        (
            "a planar inertia in 3D",
            r(
                "gravity = [0.0, -9.81, 0.0]",
                "dimensions = 3\ngravity = [0.0, -9.81, 0.0]",
            )
            .replacen("mass = 0.1", "mass = 0.1\ninertia = 0.01", 1),
            vec!["body.ball.inertia", "principal_inertia"],
        ),
        (
            "a zero orientation",
            r(
                "gravity = [0.0, -9.81, 0.0]",
                "dimensions = 3\ngravity = [0.0, -9.81, 0.0]",
            )
            .replacen(
                "mass = 0.1",
                "mass = 0.1\norientation = [0.0, 0.0, 0.0, 0.0]",
                1,
            ),
            vec!["body.ball.orientation", "non-zero quaternion"],
        ),
        (
            "a sphere without its radius",
            r("radius = 0.05\n", ""),
            vec!["body.ball.radius", "needs its radius"],
        ),
    ]
}

#[test]
fn assembly_mistakes_name_the_key() {
    let dir = tempfile::tempdir().unwrap();
    for (label, text, expect) in assembly_cases().into_iter().chain(crate::tree::bad_cases()) {
        std::fs::write(dir.path().join("m.toml"), &text).unwrap();
        let out = softarm(&["eom", "m.toml", "--json"], dir.path());
        let err = stderr(&out);
        assert!(!out.status.success(), "{label}: accepted");
        assert!(!err.contains("panicked"), "{label}: panic: {err}");
        assert!(stdout(&out).is_empty(), "{label}: printed output");
        for e in expect {
            assert!(err.contains(e), "{label}: expected `{e}` in: {err}");
        }
    }
}

/// What needs the numbers: joints that hold one freedom twice, and a
/// start the joints cannot reach, stop `simulate` before it writes
/// anything.
#[test]
fn dependent_joints_and_unreachable_starts_are_errors_before_any_output() {
    let dir = tempfile::tempdir().unwrap();
    let twice = format!(
        "{HELD}\n[[joint]]\nname = \"again\"\nkind = \"pin\"\na = \"left.tip\"\nb = \"ball\"\noffset_b = [-0.05, 0.0, 0.0]\n"
    );
    let far = HELD.replacen(
        "position = [0.45, 0.0, 0.0]",
        "position = [5.0, 0.0, 0.0]",
        1,
    );
    let cases = [
        ("redundant", twice, vec!["left_grip", "again", "dependent"]),
        (
            "unreachable",
            far,
            vec!["cannot be assembled", "joint", "apart"],
        ),
    ];
    std::fs::write(dir.path().join("m.toml"), HELD).unwrap();
    let out = softarm(&["simulate", "m.toml", "--out", "run"], dir.path());
    assert!(
        out.status.success(),
        "the good assembly runs: {}",
        stderr(&out)
    );
    for (label, text, expect) in cases {
        std::fs::write(dir.path().join("m.toml"), &text).unwrap();
        let out = softarm(&["simulate", "m.toml", "--out", "bad"], dir.path());
        let err = stderr(&out);
        assert!(!out.status.success(), "{label}: accepted");
        assert!(!err.contains("panicked"), "{label}: panic: {err}");
        for e in expect {
            assert!(err.contains(e), "{label}: expected `{e}` in: {err}");
        }
        assert!(!dir.path().join("bad").exists(), "{label}: wrote output");
    }
}

/// (label, file text, extra CLI args, expected fragments of stderr).
/// (label, file text, expected fragments of stderr).
type FileCase = (&'static str, String, Vec<&'static str>);

/// (label, file text, extra CLI args, expected fragments of stderr).
type CliCase = (&'static str, String, Vec<&'static str>, Vec<&'static str>);

fn cases() -> Vec<CliCase> {
    let mut all = syntax_value_and_section_cases();
    all.extend(simulate_tip_and_stiffness_cases());
    all.extend(override_and_sensor_cases());
    all
}

fn syntax_value_and_section_cases() -> Vec<CliCase> {
    let r = |a: &str, b: &str| GOOD.replacen(a, b, 1);
    vec![
        (
            "toml syntax",
            r("length = 0.3", "length = = 0.3"),
            vec![],
            vec!["m.toml", "invalid TOML", "line"],
        ),
        (
            "unknown top-level key",
            format!("colour = 1\n{GOOD}"),
            vec![],
            vec!["unknown field `colour`", "expected one of"],
        ),
        (
            "unknown segment key",
            r("length = 0.3", "lenght = 0.3"),
            vec![],
            vec![
                "segment[0]",
                "unknown field `lenght`",
                "did you mean `length`?",
            ],
        ),
        (
            "wrong type",
            r("length = 0.3", "length = \"long\""),
            vec![],
            vec!["segment[0].length", "invalid type: string"],
        ),
        (
            "negative length",
            r("length = 0.3", "length = -0.3"),
            vec![],
            vec!["segment[0].length", "must be positive"],
        ),
        (
            "zero elements",
            r("elements = 2", "elements = 0"),
            vec![],
            vec!["segment[0].elements", "between 1 and"],
        ),
        (
            "fractional elements",
            r("elements = 2", "elements = 2.5"),
            vec![],
            vec!["segment[0].elements", "invalid type"],
        ),
        (
            "NaN mass",
            r("mass = 0.5", "mass = nan"),
            vec![],
            vec!["segment[0].mass", "finite"],
        ),
        (
            "infinite gravity",
            r("[0.0, -9.81, 0.0]", "[0.0, -inf, 0.0]"),
            vec![],
            vec!["gravity[1]", "finite"],
        ),
        (
            "zero base direction",
            r("[0.0, -1.0, 0.0]", "[0.0, 0.0, 0.0]"),
            vec![],
            vec!["base.direction", "non-zero"],
        ),
        (
            "out-of-plane direction",
            r("[0.0, -1.0, 0.0]", "[0.0, -1.0, 0.5]"),
            vec![],
            vec!["base.direction", "x-y plane"],
        ),
        (
            "unknown method",
            r("\"rigid\"", "\"spaghetti\""),
            vec![],
            vec!["segment[0].method", "unknown variant `spaghetti`", "rigid"],
        ),
        (
            "no mass",
            r("mass = 0.5\n", ""),
            vec![],
            vec!["segment[0].mass", "missing", "density"],
        ),
        (
            "mass and density",
            r(
                "mass = 0.5",
                "mass = 0.5\ndensity = 1000.0\nouter_radius = 0.01",
            ),
            vec![],
            vec!["segment[0].mass", "either"],
        ),
        (
            "density without radius",
            r("mass = 0.5", "density = 1000.0"),
            vec![],
            vec!["segment[0].outer_radius", "missing"],
        ),
        (
            "inner radius too large",
            r(
                "mass = 0.5",
                "density = 1000.0\nouter_radius = 0.01\ninner_radius = 0.02",
            ),
            vec![],
            vec!["segment[0].inner_radius", "smaller than outer_radius"],
        ),
        (
            "negative stiffness",
            r("joint_stiffness = 1.0", "joint_stiffness = -1.0"),
            vec![],
            vec!["segment[0].joint_stiffness", "zero or positive"],
        ),
    ]
}

fn simulate_tip_and_stiffness_cases() -> Vec<CliCase> {
    let r = |a: &str, b: &str| GOOD.replacen(a, b, 1);
    vec![
        (
            "unknown solver in [simulate]",
            format!("{GOOD}[simulate]\nsolver = \"ode45\"\n"),
            vec![],
            vec![
                "simulate.solver",
                "unknown solver \"ode45\"",
                "radau5",
                "trbdf2",
            ],
        ),
        (
            "negative tolerance in [simulate]",
            format!("{GOOD}[simulate]\nrtol = -1e-6\n"),
            vec![],
            vec!["simulate.rtol", "must be positive"],
        ),
        (
            "unknown key in [simulate]",
            format!("{GOOD}[simulate]\nintegrator = \"radau5\"\n"),
            vec![],
            vec!["unknown field `integrator`", "solver"],
        ),
        (
            "negative tip mass",
            r("mass = 0.1", "mass = -0.1"),
            vec![],
            vec!["tip.mass"],
        ),
        (
            "missing gravity",
            r("gravity = [0.0, -9.81, 0.0]\n", ""),
            vec![],
            vec!["missing field `gravity`"],
        ),
        (
            "short vector",
            r("[0.0, -9.81, 0.0]", "[0.0, -9.81]"),
            vec![],
            vec!["gravity", "invalid length 2"],
        ),
        (
            "no segments",
            format!(
                "segment = []\n{}",
                GOOD.split("[[segment]]").next().unwrap()
            ),
            vec![],
            vec!["segment", "at least one"],
        ),
        (
            "pcc with a joint spring",
            r("\"rigid\"", "\"pcc\""),
            vec![],
            vec!["segment[0].joint_stiffness", "not a key of pcc segments"],
        ),
        (
            "pcc without stiffness",
            r("\"rigid\"", "\"pcc\"")
                .replace("joint_stiffness = 1.0\n", "")
                .replace("joint_damping = 0.1\n", ""),
            vec![],
            vec!["segment[0].youngs_modulus", "missing"],
        ),
        (
            "modulus without radius",
            r("joint_stiffness = 1.0", "youngs_modulus = 1e6"),
            vec![],
            vec!["segment[0].outer_radius", "youngs_modulus"],
        ),
        (
            "modulus and EI",
            r(
                "joint_stiffness = 1.0",
                "youngs_modulus = 1e6\nbending_stiffness = 0.1\nouter_radius = 0.01",
            ),
            vec![],
            vec!["segment[0].bending_stiffness", "either"],
        ),
        (
            "joint spring and EI",
            r(
                "joint_stiffness = 1.0",
                "joint_stiffness = 1.0\nbending_stiffness = 0.1",
            ),
            vec![],
            vec!["segment[0].joint_stiffness", "not both"],
        ),
        (
            "negative bending damping",
            r("joint_damping = 0.1", "bending_damping = -1.0"),
            vec![],
            vec!["segment[0].bending_damping", "zero or positive"],
        ),
        (
            "unknown joint placement",
            r(
                "joint_damping = 0.1",
                "joint_damping = 0.1\njoints = \"elbow\"",
            ),
            vec![],
            vec!["segment[0].joints", "unknown variant `elbow`", "midpoint"],
        ),
    ]
}

fn override_and_sensor_cases() -> Vec<CliCase> {
    let r = |a: &str, b: &str| GOOD.replacen(a, b, 1);
    vec![
        (
            "set without =",
            GOOD.into(),
            vec!["--set", "segment.0.length"],
            vec!["--set", "PATH=VALUE"],
        ),
        (
            "set index out of range",
            GOOD.into(),
            vec!["--set", "segment.5.length=1"],
            vec!["segment.5.length", "out of range", "1 items"],
        ),
        (
            "set unknown key",
            GOOD.into(),
            vec!["--set", "segment.0.lenght=1"],
            vec!["segment[0]", "unknown field `lenght`"],
        ),
        (
            "set negative value",
            GOOD.into(),
            vec!["--set", "segment.0.length=-1"],
            vec!["segment[0].length", "must be positive"],
        ),
        (
            "set non-index",
            GOOD.into(),
            vec!["--set", "segment.first.length=1"],
            vec![
                "segment.first.length",
                "neither an index nor an item's name",
            ],
        ),
        (
            "set wrong type",
            GOOD.into(),
            vec!["--set", "tip.mass=heavy"],
            vec!["tip.mass", "invalid type: string"],
        ),
        (
            "set inside a value",
            GOOD.into(),
            vec!["--set", "name.x=1"],
            vec!["name.x", "is a value"],
        ),
        (
            "set zero elements",
            GOOD.into(),
            vec!["--set", "segment.0.elements=0"],
            vec!["segment[0].elements"],
        ),
        (
            "sensor axes that are no axes",
            r(
                "force = [0.0, 0.0, 0.0]",
                "force = [0.0, 0.0, 0.0]\nsensor_rotation = [\"x\", \"up\", \"z\"]",
            ),
            vec![],
            vec!["tip.sensor_rotation", "`up` is not an axis"],
        ),
        (
            "sensor axes that reflect",
            r(
                "force = [0.0, 0.0, 0.0]",
                "force = [0.0, 0.0, 0.0]\nsensor_rotation = [\"x\", \"z\", \"y\"]",
            ),
            vec![],
            vec!["tip.sensor_rotation", "right-handed"],
        ),
        (
            "sensor matrix that is no rotation",
            r(
                "force = [0.0, 0.0, 0.0]",
                "force = [0.0, 0.0, 0.0]\nsensor_rotation = [[1.0, 0.0, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, 1.0]]",
            ),
            vec![],
            vec!["tip.sensor_rotation", "orthonormal"],
        ),
        (
            "sensor in the world frame",
            r(
                "force = [0.0, 0.0, 0.0]",
                "force = [0.0, 0.0, 0.0]\nsensor_offset = [0.0, 0.01, 0.0]\nwrench_frame = \"world\"",
            ),
            vec![],
            vec!["tip.wrench_frame", "sensor frame sits on the tip"],
        ),
        (
            "set a misspelt input channel",
            format!(
                "{GOOD}\n[inputs.load]\nkind = \"constant\"\nvalue = 0.0\n[inputs.push]\nkind = \"constant\"\nvalue = 1.0\n"
            ),
            vec!["--set", "inputs.lod.value=2"],
            vec![
                "inputs.lod.value",
                "`inputs` has no entry `lod`",
                "load, push",
            ],
        ),
        (
            "set bad value",
            GOOD.into(),
            vec!["--set", "tip.force=[0,"],
            vec!["tip.force", "cannot read the value"],
        ),
        (
            "wrong --q length",
            GOOD.into(),
            vec!["--q", "0.1"],
            vec!["--q", "expected 2 values"],
        ),
        (
            "non-numeric --q",
            GOOD.into(),
            vec!["--q", "0.1,abc"],
            vec!["--q", "comma-separated numbers"],
        ),
    ]
}

#[test]
fn malformed_models_and_overrides_are_rejected_clearly() {
    let dir = tempfile::tempdir().unwrap();
    let cases = cases();
    assert!(cases.len() >= 15);
    for (label, text, extra, expect) in cases {
        std::fs::write(dir.path().join("m.toml"), &text).unwrap();
        let mut args = vec!["eom", "m.toml", "--json"];
        args.extend(extra);
        let out = softarm(&args, dir.path());
        let err = stderr(&out);
        assert!(!out.status.success(), "{label}: accepted");
        assert!(!err.contains("panicked"), "{label}: panic: {err}");
        assert!(
            stdout(&out).is_empty(),
            "{label}: printed output on failure"
        );
        for e in expect {
            assert!(err.contains(e), "{label}: expected `{e}` in: {err}");
        }
    }
}

#[test]
fn the_good_model_is_accepted() {
    // The baseline of the table above really is valid.
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("m.toml"), GOOD).unwrap();
    let out = softarm(&["eom", "m.toml", "--json"], dir.path());
    assert!(out.status.success(), "{}", stderr(&out));
}

#[test]
fn json_models_are_accepted_and_json_errors_located() {
    let dir = tempfile::tempdir().unwrap();
    let good = serde_json::json!({
        "name": "j", "gravity": [0.0, -9.81, 0.0], "base": {"direction": [1.0, 0.0, 0.0]},
        "segment": [{"method": "rigid", "length": 0.2, "elements": 2, "mass": 0.1}]
    });
    std::fs::write(dir.path().join("j.json"), good.to_string()).unwrap();
    let out = softarm(&["eom", "j.json", "--json"], dir.path());
    assert!(out.status.success(), "{}", stderr(&out));
    std::fs::write(dir.path().join("bad.json"), "{\"name\": ").unwrap();
    let out = softarm(&["eom", "bad.json"], dir.path());
    assert!(!out.status.success());
    assert!(
        stderr(&out).contains("bad.json: invalid JSON"),
        "{}",
        stderr(&out)
    );
}

#[test]
fn missing_model_names_the_compiled_in_ones() {
    let dir = tempfile::tempdir().unwrap();
    let out = softarm(&["eom", "no_such_arm"], dir.path());
    assert!(!out.status.success());
    let err = stderr(&out);
    assert!(
        err.contains("no_such_arm") && err.contains("double_pendulum"),
        "{err}"
    );
}

#[test]
fn failed_simulation_writes_no_partial_files() {
    // A rejected option fails before anything is written.
    let dir = tempfile::tempdir().unwrap();
    let out = softarm(
        &["simulate", "chain", "--t-end", "-1", "--out", "o"],
        dir.path(),
    );
    assert!(!out.status.success());
    assert!(stderr(&out).contains("--t-end"));
    assert!(!dir.path().join("o/summary.json").exists());
}

#[test]
fn bad_simulate_options_are_rejected_clearly() {
    let dir = tempfile::tempdir().unwrap();
    for (args, expect) in [
        (vec!["--rtol=-1e-6"], "--rtol must be positive"),
        (vec!["--t-end", "0"], "--t-end must be a positive number"),
        (vec!["--max-steps", "0"], "--max-steps must be at least 1"),
        (vec!["--solver", "ode45"], "possible values"),
        (
            vec!["--shape-points", "1000"],
            "--shape-points 1000: must be 1 to 64",
        ),
    ] {
        let mut all = vec!["simulate", "double_pendulum", "--out", "o"];
        all.extend(&args);
        let out = softarm(&all, dir.path());
        assert!(!out.status.success(), "{args:?}");
        let err = stderr(&out);
        assert!(
            err.contains(expect),
            "{args:?}: expected `{expect}` in: {err}"
        );
        assert!(!err.contains("panicked"), "{args:?}: {err}");
        // Refused before the run: nothing written.
        assert!(!dir.path().join("o/trajectory.csv").exists(), "{args:?}");
    }
}

const GOOD3: &str = r#"
name = "t3"
dimensions = 3
gravity = [0.0, 0.0, -9.81]
[base]
direction = [1.0, 0.0, 0.0]
[[segment]]
method = "pcc"
length = 0.3
elements = 2
density = 1000.0
outer_radius = 0.01
youngs_modulus = 1e6
"#;

/// A section given by its properties, all valid.
const PROPERTIES: &str = "{ shape = \"properties\", axial_stiffness = 300.0, bending_stiffness = [1e-3, 2e-3], torsional_stiffness = 1e-3, mass_per_length = 0.3, rotary_inertia = [1e-6, 1e-6] }";

/// The cases of `malformed_3d_models_are_rejected_clearly`.
fn three_d_cases() -> Vec<FileCase> {
    let mut all = three_d_key_cases();
    all.extend(shape_and_load_cases());
    all.extend(section_load_and_fluid_cases());
    all.extend(three_d_method_cases());
    all
}

/// Sections, loads along the arm and the fluid.
fn section_load_and_fluid_cases() -> Vec<FileCase> {
    let r = |a: &str, b: &str| GOOD3.replacen(a, b, 1);
    vec![
        (
            "a section and a radius",
            r(
                "outer_radius = 0.01",
                "outer_radius = 0.01\nsection = { shape = \"ellipse\", width = 0.01, height = 0.01 }",
            ),
            vec!["segment[0].outer_radius", "takes no `outer_radius`"],
        ),
        (
            "a section of no width",
            r(
                "outer_radius = 0.01",
                "section = { shape = \"rectangle\", width = 0.0, height = 0.01 }",
            ),
            vec!["segment[0].section.width", "must be positive"],
        ),
        (
            "properties and a density",
            r("outer_radius = 0.01", &format!("section = {PROPERTIES}")),
            vec!["segment[0].density", "takes no `density`"],
        ),
        (
            "properties with a zero rotary inertia",
            r(
                "density = 1000.0\nouter_radius = 0.01\nyoungs_modulus = 1e6",
                &format!(
                    "section = {}",
                    PROPERTIES.replace("[1e-6, 1e-6]", "[0.0, 1e-6]")
                ),
            ),
            vec!["segment[0].section.rotary_inertia[0]", "must be positive"],
        ),
        (
            "properties with three shear stiffnesses",
            r(
                "density = 1000.0\nouter_radius = 0.01\nyoungs_modulus = 1e6",
                &format!(
                    "section = {}",
                    PROPERTIES.replace(
                        "axial_stiffness",
                        "shear_stiffness = [5.0, 5.0, 5.0], axial_stiffness"
                    )
                ),
            ),
            vec!["segment[0].section", "`shear_stiffness`: a number, or two"],
        ),
        (
            "properties with a negative shear stiffness along z",
            r(
                "density = 1000.0\nouter_radius = 0.01\nyoungs_modulus = 1e6",
                &format!(
                    "section = {}\nshear = true",
                    PROPERTIES.replace(
                        "axial_stiffness",
                        "shear_stiffness = [5.0, -5.0], axial_stiffness"
                    )
                ),
            ),
            vec!["segment[0].section.shear_stiffness", "must be positive"],
        ),
        (
            "properties of a shearing segment without its shear stiffness",
            r(
                "density = 1000.0\nouter_radius = 0.01\nyoungs_modulus = 1e6",
                &format!("section = {PROPERTIES}\nshear = true"),
            ),
            vec!["segment[0].section.shear_stiffness", "missing"],
        ),
        (
            "load off its segment",
            format!(
                "{}[[load]]\nsegment = 0\ns = 0.5\nforce = [0.0, 0.0, -1.0]\n",
                GOOD3
            ),
            vec!["load[0].s", "between 0 and its length 0.3 m"],
        ),
        (
            "load on no segment",
            format!(
                "{}[[load]]\nsegment = 3\ns = 0.1\nforce = [0.0, 0.0, -1.0]\n",
                GOOD3
            ),
            vec!["load[0].segment", "no segment 3"],
        ),
        (
            "load without force",
            format!("{}[[load]]\nsegment = 0\ns = 0.1\n", GOOD3),
            vec!["load[0].force", "missing"],
        ),
        (
            "point load on the Cosserat rod",
            format!(
                "{}[[load]]\nsegment = 0\ns = 0.1\nforce = [0.0, 0.0, -1.0]\n",
                GOOD3
            )
            .replace("\"pcc\"", "\"cosserat\""),
            vec!["load[0].s", "constant distributed force"],
        ),
        (
            "fluid of negative density",
            format!("{}[fluid]\ndensity = -1.0\n", GOOD3),
            vec!["fluid.density", "zero or positive"],
        ),
        (
            "fluid around an arm without a radius",
            format!("{}[fluid]\ndensity = 1000.0\n", GOOD3)
                .replace(
                    "density = 1000.0\nouter_radius = 0.01",
                    "mass = 0.1\nbending_stiffness = 0.1\ntorsional_stiffness = 0.1",
                )
                .replace("youngs_modulus = 1e6\n", ""),
            vec!["segment[0].outer_radius", "immersed"],
        ),
        (
            "distributed moment",
            format!("{}[[load]]\nsegment = 0\nmoment = [0.0, 0.0, 1.0]\n", GOOD3),
            vec!["load[0].moment", "per unit length"],
        ),
    ]
}

/// Rest shapes and kinks.
fn shape_and_load_cases() -> Vec<FileCase> {
    let r = |a: &str, b: &str| GOOD3.replacen(a, b, 1);
    vec![
        (
            "rest twist in 2D",
            r("dimensions = 3\n", "")
                .replace("elements = 2", "elements = 2\nrest_twist = 1.0")
                .replace("-9.81]", "0.0]"),
            vec!["segment[0].rest_twist", "a 3D key"],
        ),
        (
            "rest curvature vector in 2D",
            r("dimensions = 3\n", "")
                .replace(
                    "elements = 2",
                    "elements = 2\nrest_curvature = [0.0, [1.0, 2.0]]",
                )
                .replace("-9.81]", "0.0]"),
            vec!["segment[0].rest_curvature", "one axis"],
        ),
        (
            "rest stretch without extension",
            r("elements = 2", "elements = 2\nrest_stretch = 0.1"),
            vec!["segment[0].rest_stretch", "extension = true"],
        ),
        (
            "rest stretch to nothing",
            r(
                "elements = 2",
                "elements = 2\nextension = true\nrest_stretch = -1.5",
            ),
            vec!["segment[0].rest_stretch", "above -1"],
        ),
        (
            "rest curvature of three",
            r(
                "elements = 2",
                "elements = 2\nrest_curvature = [1.0, 2.0, 3.0]",
            ),
            vec!["segment[0].rest_curvature", "give two values"],
        ),
        (
            "turn of one angle in 3D",
            r("elements = 2", "elements = 2\nturn = [90.0]"),
            vec!["segment[0].turn", "[angle about y, angle about z] in 3D"],
        ),
        (
            "turn of two angles in the plane",
            r("dimensions = 3\n", "")
                .replace("elements = 2", "elements = 2\nturn = [0.0, 90.0]")
                .replace("-9.81]", "0.0]"),
            vec!["segment[0].turn", "[angle about z] in the plane"],
        ),
        (
            "offset out of the plane",
            r("dimensions = 3\n", "")
                .replace("elements = 2", "elements = 2\noffset = [0.0, 0.01, 0.01]")
                .replace("-9.81]", "0.0]"),
            vec!["segment[0].offset", "z must be 0"],
        ),
        (
            "eba kinked",
            r("\"pcc\"", "\"eba\"").replace("elements = 2", "elements = 2\nturn = [0.0, 90.0]"),
            vec!["segment[0].turn", "meet tangent"],
        ),
        (
            "relaxation ratio of one",
            r(
                "elements = 2",
                "elements = 2\nrelaxation = [{ ratio = 1.0, time = 0.5 }]",
            ),
            vec!["segment[0].relaxation[0].ratio", "between 0 and 1"],
        ),
        (
            "relaxation ratios summing to one",
            r(
                "elements = 2",
                "elements = 2\nrelaxation = [{ ratio = 0.6, time = 0.5 }, { ratio = 0.4, time = 2.0 }]",
            ),
            vec!["segment[0].relaxation", "sum below 1"],
        ),
        (
            "relaxation time of zero",
            r(
                "elements = 2",
                "elements = 2\nrelaxation = [{ ratio = 0.3, time = 0.0 }]",
            ),
            vec!["segment[0].relaxation[0].time", "positive"],
        ),
        (
            "relaxation without a time",
            r(
                "elements = 2",
                "elements = 2\nrelaxation = [{ ratio = 0.3 }]",
            ),
            vec!["time"],
        ),
        (
            "relaxation with contact",
            r(
                "elements = 2",
                "elements = 2\nrelaxation = [{ ratio = 0.3, time = 0.5 }]",
            ) + "[[obstacle]]\nname = \"floor\"\nshape = \"plane\"\npoint = [0.0, 0.0, -0.5]\nnormal = [0.0, 0.0, 1.0]\n",
            vec!["segment[0].relaxation", "contact"],
        ),
    ]
}

fn three_d_key_cases() -> Vec<FileCase> {
    let r = |a: &str, b: &str| GOOD3.replacen(a, b, 1);
    vec![
        (
            "dimensions 4",
            r("dimensions = 3", "dimensions = 4"),
            vec!["dimensions", "must be 2 (planar) or 3"],
        ),
        (
            "ebr in 2D",
            r("dimensions = 3\n", "")
                .replace("\"pcc\"", "\"ebr\"")
                .replace("-9.81]", "0.0]"),
            vec!["segment[0].method", "ebr is a 3D method", "dimensions = 3"],
        ),
        (
            "twist in 2D",
            r("dimensions = 3\n", "")
                .replace("elements = 2", "elements = 2\ntwist = false")
                .replace("-9.81]", "0.0]"),
            vec!["segment[0].twist", "a 3D key"],
        ),
        (
            "shear in 2D",
            r("dimensions = 3\n", "")
                .replace("elements = 2", "elements = 2\nshear = true")
                .replace("-9.81]", "0.0]"),
            vec!["segment[0].shear", "a 3D key"],
        ),
        (
            "pcs in 2D",
            r("dimensions = 3\n", "")
                .replace("\"pcc\"", "\"pcs\"")
                .replace("-9.81]", "0.0]"),
            vec!["segment[0].method", "pcs is a 3D method", "dimensions = 3"],
        ),
        (
            "shear on ebr",
            r("method = \"pcc\"", "method = \"ebr\"\nshear = true"),
            vec![
                "segment[0].shear",
                "ebr segments carry no shear strain",
                "shear is for pcc, pcs, vc, rom and cosserat segments",
            ],
        ),
        (
            "eba without shear",
            r("method = \"pcc\"", "method = \"eba\"\nshear = false"),
            vec!["segment[0].shear", "eba elements always shear"],
        ),
        (
            "zero shear factor",
            r("method = \"pcc\"", "method = \"pcs\"\nshear_factor = 0.0"),
            vec!["segment[0].shear_factor", "positive"],
        ),
        (
            "negative shear factor",
            r(
                "elements = 2",
                "elements = 2\nshear = true\nshear_factor = -0.9",
            ),
            vec!["segment[0].shear_factor", "positive"],
        ),
        (
            "shear factor without shear",
            r("elements = 2", "elements = 2\nshear_factor = 0.9"),
            vec!["segment[0].shear_factor", "set `shear = true`"],
        ),
        (
            "rom order 12",
            r("method = \"pcc\"", "method = \"rom\"\norder = 12"),
            vec!["segment[0].order", "between 0 and 8"],
        ),
        (
            "order on pcc",
            r("elements = 2", "order = 2"),
            vec!["segment[0].order", "only rom segments"],
        ),
    ]
}

fn three_d_method_cases() -> Vec<FileCase> {
    let r = |a: &str, b: &str| GOOD3.replacen(a, b, 1);
    let second = "\n[[segment]]\nmethod = \"pcc\"\nlength = 0.1\ndensity = 1000.0\nouter_radius = 0.01\nyoungs_modulus = 1e6\n";
    vec![
        (
            "eba mixed",
            format!("{}{second}", r("method = \"pcc\"", "method = \"eba\"")),
            vec!["segment[0].method", "every segment of the arm must be eba"],
        ),
        (
            "four joint axes",
            r(
                "method = \"pcc\"",
                "method = \"rigid\"\njoint_axes = [\"x\", \"y\", \"z\", \"x\"]",
            ),
            vec!["segment[0].joint_axes", "1 to 3 axes"],
        ),
        (
            "a joint axis twice",
            r(
                "method = \"pcc\"",
                "method = \"rigid\"\njoint_axes = [\"z\", \"y\", \"z\"]",
            ),
            vec!["segment[0].joint_axes", "each axis once", "z twice"],
        ),
        (
            "joint axes on pcc",
            r("elements = 2", "joint_axes = [\"z\"]"),
            vec!["segment[0].joint_axes", "only rigid segments"],
        ),
        (
            "unknown axis",
            r(
                "method = \"pcc\"",
                "method = \"rigid\"\njoint_axes = [\"w\"]",
            ),
            vec!["segment[0].joint_axes", "unknown variant `w`"],
        ),
        (
            "twist without G J",
            r("youngs_modulus = 1e6", "bending_stiffness = 0.01"),
            vec!["segment[0].torsional_stiffness", "missing"],
        ),
        (
            "cosserat dynamics",
            r("method = \"pcc\"", "method = \"cosserat\""),
            vec!["cosserat", "softarm static"],
        ),
        (
            "unknown method",
            r("method = \"pcc\"", "method = \"fem\""),
            vec!["segment[0].method", "unknown variant `fem`", "rom"],
        ),
        (
            "chambers that turn the principal axes",
            r(
                "elements = 2",
                "chambers = { angles = [0, 90], radius = 0.002, distance = 0.005 }",
            ),
            vec!["segment[0].chambers", "principal axes", "0 and 180"],
        ),
        (
            "overlapping chambers",
            r(
                "elements = 2",
                "chambers = { count = 8, radius = 0.002, distance = 0.005 }",
            ),
            vec!["segment[0].chambers", "overlap"],
        ),
        (
            "incompressible Cosserat rod",
            r(
                "method = \"pcc\"",
                "method = \"cosserat\"\nincompressible = true",
            ),
            vec!["segment[0].incompressible", "keeps its section"],
        ),
        (
            "Cosserat rod without twist stiffness",
            r("method = \"pcc\"", "method = \"cosserat\"\ntwist = false")
                .replace("youngs_modulus = 1e6", "bending_stiffness = 0.01"),
            vec!["segment[0].torsional_stiffness", "missing", "Cosserat"],
        ),
        (
            "chamber outside the wall",
            r(
                "elements = 2",
                "chambers = { count = 3, radius = 0.002, distance = 0.009 }",
            ),
            vec!["segment[0].chambers", "must lie in the wall"],
        ),
    ]
}

#[test]
fn malformed_3d_models_are_rejected_clearly() {
    let dir = tempfile::tempdir().unwrap();
    let r = |a: &str, b: &str| GOOD3.replacen(a, b, 1);
    let second = "\n[[segment]]\nmethod = \"pcc\"\nlength = 0.1\ndensity = 1000.0\nouter_radius = 0.01\nyoungs_modulus = 1e6\n";
    let cases = three_d_cases();
    assert_rejected(dir.path(), cases);
    // The baseline is valid, and the Cosserat statics reject what they
    // cannot model.
    std::fs::write(dir.path().join("m.toml"), GOOD3).unwrap();
    assert!(
        softarm(&["static", "m.toml", "--json"], dir.path())
            .status
            .success()
    );
    std::fs::write(
        dir.path().join("m.toml"),
        format!("{}{second}", r("method = \"pcc\"", "method = \"cosserat\"")),
    )
    .unwrap();
    let out = softarm(&["static", "m.toml", "--json"], dir.path());
    assert!(!out.status.success());
    assert!(
        stderr(&out).contains("segment: the Cosserat statics take one [[segment]], got 2"),
        "{}",
        stderr(&out)
    );
}

/// The cases of `malformed_actuators_inputs_and_measurements_are_rejected_clearly`.
fn actuator_input_and_measurement_cases() -> Vec<FileCase> {
    let mut all = chamber_and_input_cases();
    all.extend(taper_cases());
    all.extend(tendon_torque_and_measurement_cases());
    all
}

/// Tapered sections: values through zero, malformed tapers, holes or an
/// inner radius that leave the section where it thins.
fn taper_cases() -> Vec<FileCase> {
    let chambers = "[segment.chambers]\nangles = [0, 120, 240]\nradius = 0.002\ndistance = 0.006\ninputs = [\"p\", \"p\", \"p\"]\n";
    let channel = "[inputs.p]\nkind = \"constant\"\nvalue = 1.0\n";
    let base = format!("{GOOD3}{chambers}{channel}");
    let r = |a: &str, b: &str| base.replacen(a, b, 1);
    vec![
        (
            "taper through zero",
            r("outer_radius = 0.01", "outer_radius = [0.01, -0.002]"),
            vec![
                "segment[0].outer_radius",
                "must be positive everywhere along the segment, got -0.002",
            ],
        ),
        (
            "taper of three numbers",
            r("outer_radius = 0.01", "outer_radius = [0.01, 0.008, 0.006]"),
            vec!["segment[0].outer_radius", "[start, end], two numbers"],
        ),
        (
            "taper table not rising",
            r(
                "outer_radius = 0.01",
                "outer_radius = { s = [0.0, 0.6, 0.5, 1.0], value = [0.01, 0.009, 0.008, 0.007] }",
            ),
            vec!["segment[0].outer_radius", "rising from 0 to 1"],
        ),
        (
            "holes outside a tapered section",
            r("outer_radius = 0.01", "outer_radius = [0.01, 0.007]"),
            vec![
                "segment[0].chambers",
                "must lie in the wall",
                "outer radius 0.007",
                "at s/L = 1",
            ],
        ),
        (
            "inner radius below zero",
            r(
                "outer_radius = 0.01",
                "outer_radius = 0.01\ninner_radius = -0.001",
            ),
            vec!["segment[0].inner_radius", "zero or positive"],
        ),
        (
            "tapered inner radius reaching the outer",
            r(
                "outer_radius = 0.01",
                "outer_radius = [0.01, 0.006]\ninner_radius = [0.001, 0.007]",
            ),
            vec![
                "segment[0].inner_radius",
                "smaller than outer_radius",
                "at s/L = 1",
            ],
        ),
    ]
}

fn chamber_and_input_cases() -> Vec<FileCase> {
    let chambers = "[segment.chambers]\nangles = [0, 120, 240]\nradius = 0.002\ndistance = 0.006\ninputs = [\"p\", \"p\", \"p\"]\n";
    let channel = "[inputs.p]\nkind = \"constant\"\nvalue = 1.0\n";
    let base = format!("{GOOD3}{chambers}{channel}");
    let r = |a: &str, b: &str| base.replacen(a, b, 1);
    vec![
        (
            "anisotropic holes",
            r("angles = [0, 120, 240]", "angles = [0, 90, 240]"),
            vec!["segment[0].chambers", "principal axes"],
        ),
        (
            "a chamber offset tapering out of the wall",
            r("distance = 0.006", "distance = [0.006, 0.02]"),
            vec!["segment[0].chambers", "must lie in the wall", "at s/L = 1"],
        ),
        (
            "radii not one per position",
            r("radius = 0.002", "radius = [0.002, 0.001]"),
            vec!["segment[0].chambers.radius", "one per position (3), got 2"],
        ),
        (
            "a radius of zero",
            r("radius = 0.002", "radius = [0.002, 0.0, 0.002]"),
            vec!["segment[0].chambers.radius", "must be positive, got 0"],
        ),
        (
            "holes of unequal radii overlapping",
            r(
                "angles = [0, 120, 240]\nradius = 0.002",
                "angles = [0, 60, 240]\nradius = [0.0035, 0.0035, 0.002]",
            ),
            vec!["segment[0].chambers", "overlap"],
        ),
        (
            "count and angles",
            r(
                "angles = [0, 120, 240]",
                "count = 3\nangles = [0, 120, 240]",
            ),
            vec!["segment[0].chambers.angles", "not both"],
        ),
        (
            "inputs per position",
            r("inputs = [\"p\", \"p\", \"p\"]", "inputs = [\"p\"]"),
            vec![
                "segment[0].chambers.inputs",
                "one input channel per position",
            ],
        ),
        (
            "undeclared channel",
            r(
                "inputs = [\"p\", \"p\", \"p\"]",
                "inputs = [\"p\", \"q\", \"p\"]",
            ),
            vec![
                "segment[0].chambers.inputs[1]",
                "no input channel \"q\"",
                "declared: p",
            ],
        ),
        (
            "pair spacing",
            r("distance = 0.006", "distance = 0.006\npair_spacing = 95"),
            vec!["segment[0].chambers.pair_spacing", "between 0 and 90"],
        ),
        (
            "unknown signal kind",
            r("kind = \"constant\"", "kind = \"square\""),
            vec!["inputs.p", "unknown variant `square`", "csv"],
        ),
        (
            "ramp backwards",
            r(
                "kind = \"constant\"\nvalue = 1.0",
                "kind = \"ramp\"\nto = 1.0\nstart = 2.0\nend = 1.0",
            ),
            vec!["inputs.p.end", "must be after start"],
        ),
        (
            "csv offset word",
            r(
                "kind = \"constant\"\nvalue = 1.0",
                "kind = \"csv\"\nfile = \"d.csv\"\ncolumn = \"P\"\noffset = \"last\"",
            ),
            vec!["inputs.p.offset", "\"first\""],
        ),
        (
            "csv missing column",
            r(
                "kind = \"constant\"\nvalue = 1.0",
                "kind = \"csv\"\nfile = \"ok.csv\"\ncolumn = \"Q\"",
            ),
            vec!["inputs.p.column", "no column \"Q\"", "time, P, X"],
        ),
        (
            "csv not a number",
            r(
                "kind = \"constant\"\nvalue = 1.0",
                "kind = \"csv\"\nfile = \"d.csv\"\ncolumn = \"P\"",
            ),
            vec!["d.csv", "row 3", "`x` is not a number"],
        ),
        (
            "csv time backwards",
            r(
                "kind = \"constant\"\nvalue = 1.0",
                "kind = \"csv\"\nfile = \"back.csv\"\ncolumn = \"P\"",
            ),
            vec!["back.csv", "must increase", "row 4"],
        ),
        (
            "csv missing file",
            r(
                "kind = \"constant\"\nvalue = 1.0",
                "kind = \"csv\"\nfile = \"none.csv\"\ncolumn = \"P\"",
            ),
            vec!["none.csv", "cannot read"],
        ),
    ]
}

fn tendon_torque_and_measurement_cases() -> Vec<FileCase> {
    let chambers = "[segment.chambers]\nangles = [0, 120, 240]\nradius = 0.002\ndistance = 0.006\ninputs = [\"p\", \"p\", \"p\"]\n";
    let channel = "[inputs.p]\nkind = \"constant\"\nvalue = 1.0\n";
    let base = format!("{GOOD3}{chambers}{channel}");
    let r = |a: &str, b: &str| base.replacen(a, b, 1);
    vec![
        (
            "tendon past the last segment",
            format!("{base}[[tendon]]\ninput = \"p\"\ndistance = 0.005\nend = 3\n"),
            vec!["tendon[0].end", "segment index"],
        ),
        (
            "tendon outside the section",
            format!("{base}[[tendon]]\ninput = \"p\"\ndistance = 0.05\n"),
            vec!["tendon[0].distance", "outside"],
        ),
        (
            "compare rotation",
            format!(
                "{base}[compare]\nfile = \"d.csv\"\nposition = [\"X\", \"X\", \"X\"]\nrotation = [[1, 0, 0], [0, 1, 0], [0, 0, 2]]\n"
            ),
            vec!["compare.rotation", "rotation matrix"],
        ),
        (
            "sensor offset without orientation",
            format!(
                "{base}[compare]\nfile = \"d.csv\"\nposition = [\"X\", \"X\", \"X\"]\nsensor_offset = [0.01, 0, 0]\n"
            ),
            vec!["compare.sensor_offset", "orientation"],
        ),
        (
            "incompressible without extension",
            r(
                "youngs_modulus = 1e6",
                "youngs_modulus = 1e6\nincompressible = true",
            ),
            vec!["segment[0].incompressible", "extension = true"],
        ),
        (
            "tip radius without length",
            format!("{base}[tip]\nmass = 0.01\nradius = 0.005\n"),
            vec!["tip.radius", "tip.length"],
        ),
        (
            "torque on a coordinate the model lacks",
            format!("{base}[[torque]]\ncoordinate = \"theta_0_0\"\ninput = \"p\"\n"),
            vec![
                "torque[0].coordinate",
                "no coordinate \"theta_0_0\"",
                "bend_y_0_0, bend_z_0_0, twist_0_0",
            ],
        ),
        (
            "base translation inputs per axis",
            r(
                "direction = [1.0, 0.0, 0.0]",
                "direction = [1.0, 0.0, 0.0]\ntranslation_inputs = [\"p\", \"p\"]",
            ),
            vec![
                "base.translation_inputs",
                "one input channel per axis",
                "x, y, z",
            ],
        ),
        (
            "base turned by an undeclared channel",
            r(
                "direction = [1.0, 0.0, 0.0]",
                "direction = [1.0, 0.0, 0.0]\nrotation_inputs = [\"p\", \"spin\"]",
            ),
            vec!["base.rotation_inputs[1]", "no input channel \"spin\""],
        ),
        (
            "base rotation axis zero",
            r(
                "direction = [1.0, 0.0, 0.0]",
                "direction = [1.0, 0.0, 0.0]\nrotation_inputs = [\"p\"]\nrotation_axes = [[0, 0, 0]]",
            ),
            vec!["base.rotation_axes[0]", "non-zero"],
        ),
        (
            "base rotation axes per input",
            r(
                "direction = [1.0, 0.0, 0.0]",
                "direction = [1.0, 0.0, 0.0]\nrotation_inputs = [\"p\", \"p\"]\nrotation_axes = [[0, 0, 1]]",
            ),
            vec![
                "base.rotation_axes",
                "one axis per rotation input (2), got 1",
            ],
        ),
        (
            "inputs on the Cosserat statics",
            r(
                "direction = [1.0, 0.0, 0.0]",
                "direction = [1.0, 0.0, 0.0]\nrotation_inputs = [\"p\"]",
            )
            .replacen("method = \"pcc\"", "method = \"cosserat\"", 1),
            vec!["base.rotation_inputs", "Cosserat statics", "lumped method"],
        ),
        (
            "torque from an undeclared channel",
            format!("{base}[[torque]]\ncoordinate = \"bend_y_0_1\"\ninput = \"tau\"\n"),
            vec!["torque[0].input", "no input channel \"tau\""],
        ),
    ]
}

#[test]
fn malformed_actuators_inputs_and_measurements_are_rejected_clearly() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("d.csv"), "time,P,X\n0,1,0\n0.1,x,0\n").unwrap();
    std::fs::write(dir.path().join("back.csv"), "time,P\n0,1\n0.1,2\n0.05,3\n").unwrap();
    std::fs::write(dir.path().join("ok.csv"), "time,P,X\n0,1,0\n0.1,2,0\n").unwrap();
    let chambers = "[segment.chambers]\nangles = [0, 120, 240]\nradius = 0.002\ndistance = 0.006\ninputs = [\"p\", \"p\", \"p\"]\n";
    let channel = "[inputs.p]\nkind = \"constant\"\nvalue = 1.0\n";
    let base = format!("{GOOD3}{chambers}{channel}");
    let cases = actuator_input_and_measurement_cases();
    assert_rejected(dir.path(), cases);
    // The baseline is valid.
    std::fs::write(dir.path().join("m.toml"), &base).unwrap();
    let out = softarm(&["eom", "m.toml", "--json"], dir.path());
    assert!(out.status.success(), "{}", stderr(&out));
}

/// Each case's model file, given to `softarm eom`, fails without a panic or
/// output, and its message contains every expected piece.
fn assert_rejected(dir: &std::path::Path, cases: Vec<(&str, String, Vec<&str>)>) {
    for (label, text, expect) in cases {
        std::fs::write(dir.join("m.toml"), &text).unwrap();
        let out = softarm(&["eom", "m.toml", "--json"], dir);
        let err = stderr(&out);
        assert!(!out.status.success(), "{label}: accepted");
        assert!(!err.contains("panicked"), "{label}: panic: {err}");
        assert!(
            stdout(&out).is_empty(),
            "{label}: printed output on failure"
        );
        for e in expect {
            assert!(err.contains(e), "{label}: expected `{e}` in: {err}");
        }
    }
}

/// A soft arm over a table: the base of the contact cases.
const TABLE: &str = r#"
name = "tap"
gravity = [0.0, -9.81, 0.0]
[base]
direction = [1.0, 0.0, 0.0]
[[segment]]
method = "pcc"
length = 0.3
mass = 0.1
elements = 3
outer_radius = 0.01
bending_stiffness = 0.2
[[obstacle]]
name = "table"
shape = "plane"
point = [0.0, -0.1, 0.0]
normal = [0.0, 1.0, 0.0]
[contact]
model = "hunt_crossley"
stiffness = 1e4
restitution = 0.5
"#;

/// Contact mistakes: each names its key and says what is allowed, and
/// nothing is written.
#[test]
fn contact_mistakes_name_the_key() {
    let r = |from: &str, to: &str| {
        assert!(TABLE.contains(from), "{from}");
        TABLE.replacen(from, to, 1)
    };
    let cases = [
        (
            "unknown contact model",
            r("model = \"hunt_crossley\"", "model = \"velcro\""),
            vec!["contact.model", "spring_dashpot"],
        ),
        (
            "negative stiffness",
            r("stiffness = 1e4", "stiffness = -1e4"),
            vec!["contact.stiffness", "must be positive"],
        ),
        (
            "restitution above one",
            r("restitution = 0.5", "restitution = 1.5"),
            vec!["contact.restitution", "[0, 1]"],
        ),
        (
            "a plane without a direction",
            r("normal = [0.0, 1.0, 0.0]", "normal = [0.0, 0.0, 0.0]"),
            vec!["obstacle[0].normal", "zero vector"],
        ),
        (
            "a kinked arm in contact",
            r("elements = 3", "elements = 3\nturn = [30.0]"),
            vec!["segment[0].turn", "not supported yet", "weld"],
        ),
        (
            "no points per element",
            r("[contact]\n", "[contact]\npoints_per_element = 0\n"),
            vec!["contact.points_per_element", "1 to"],
        ),
        (
            "a key of another shape",
            r(
                "normal = [0.0, 1.0, 0.0]",
                "normal = [0.0, 1.0, 0.0]\nradius = 0.1",
            ),
            vec!["obstacle[0].radius", "plane obstacle takes point, normal"],
        ),
        (
            "a shape's missing key",
            r(
                "shape = \"plane\"",
                "shape = \"sphere\"\ncenter = [0.0, 0.0, 0.0]",
            ),
            vec!["obstacle[0]", "sphere obstacle"],
        ),
        (
            "a law without stiffness",
            r("stiffness = 1e4\n", ""),
            vec!["obstacle[0].contact.stiffness", "missing"],
        ),
        (
            "hunt_crossley stopped dead",
            r("restitution = 0.5", "restitution = 0.0"),
            vec!["contact.restitution", "impulse"],
        ),
        (
            "duplicate obstacle names",
            format!(
                "{TABLE}[[obstacle]]\nname = \"table\"\nshape = \"sphere\"\ncenter = [0.1, 0.0, 0.0]\nradius = 0.01\n"
            ),
            vec!["obstacle[1].name", "names of their own"],
        ),
    ];
    let dir = tempfile::tempdir().unwrap();
    for (label, text, expect) in cases {
        std::fs::write(dir.path().join("m.toml"), &text).unwrap();
        let out = softarm(&["eom", "m.toml", "--json"], dir.path());
        let err = stderr(&out);
        assert!(!out.status.success(), "{label}: accepted");
        assert!(!err.contains("panicked"), "{label}: panic: {err}");
        assert!(stdout(&out).is_empty(), "{label}: printed output");
        for e in expect {
            assert!(err.contains(e), "{label}: expected `{e}` in: {err}");
        }
    }
}

/// A start inside an obstacle stops `simulate` before it writes anything,
/// naming the obstacle and the depth; the same arm clear of it runs.
#[test]
fn a_start_inside_an_obstacle_is_an_error_before_any_output() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("m.toml"), TABLE).unwrap();
    let out = softarm(
        &["simulate", "m.toml", "--out", "run", "--t-end", "0.05"],
        dir.path(),
    );
    assert!(out.status.success(), "clear of the table: {}", stderr(&out));
    let inside = TABLE.replacen("point = [0.0, -0.1, 0.0]", "point = [0.0, 0.005, 0.0]", 1);
    std::fs::write(dir.path().join("m.toml"), inside).unwrap();
    let out = softarm(&["simulate", "m.toml", "--out", "bad"], dir.path());
    let err = stderr(&out);
    assert!(!out.status.success(), "accepted a start inside the table");
    assert!(!err.contains("panicked"), "panic: {err}");
    for e in ["inside obstacle \"table\"", "15.000 mm deep", "--q0"] {
        assert!(err.contains(e), "expected `{e}` in: {err}");
    }
    assert!(!dir.path().join("bad").exists(), "wrote output");
}
