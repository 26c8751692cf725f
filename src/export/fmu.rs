//! `softarm export MODEL --fmu FILE.fmu`: an FMI 2.0 model-exchange FMU of
//! the C library: modelDescription.xml (states, their derivatives, the
//! outputs, the parameters and inputs by name), the C sources and a
//! binary for this platform, built by the system's C compiler.

use std::fmt::Write as _;
use std::io::Write as _;
use std::path::Path;
use std::process::Command;

use anyhow::{Context, Result, bail};
use runtime::OUTPUT_NAMES;
// Named apart: the architecture test keeps the modelling methods' enum path to eomgen/src/method.
use zip::CompressionMethod as Compression;

use super::c_api::Library;
use super::c_tape::literal;

/// The FMI wrapper, the same for every model but its names.
const FMI2: &str = include_str!("fmi2.c");

/// The FMI platform folder and shared-library suffix of this machine.
fn platform() -> Result<(&'static str, &'static str)> {
    match (std::env::consts::OS, std::env::consts::ARCH) {
        ("linux", "x86_64") => Ok(("linux64", "so")),
        ("linux", "aarch64") => Ok(("aarch64-linux", "so")),
        ("macos", _) => Ok(("darwin64", "dylib")),
        (os, arch) => bail!("--fmu: no FMU binary is built on {os} {arch} yet (Linux and macOS)"),
    }
}

/// XML text with its five special characters escaped.
fn xml(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
        .replace('\'', "&apos;")
}

/// Write the FMU of `lib` to `fmu`, compiling in `build` (a folder of its
/// own, removed by the caller).
pub fn write(lib: &Library, fmu: &Path, build: &Path) -> Result<()> {
    let (folder, suffix) = platform()?;
    let id = lib.prefix;
    let wrapper = lib.named(FMI2);
    let files = [
        (format!("{id}.h"), lib.header()),
        (format!("{id}.c"), lib.source()),
        ("fmi2.c".to_string(), wrapper),
    ];
    std::fs::create_dir_all(build).with_context(|| format!("creating {}", build.display()))?;
    for (name, text) in &files {
        std::fs::write(build.join(name), text)
            .with_context(|| format!("writing {}", build.join(name).display()))?;
    }
    let binary = build.join(format!("{id}.{suffix}"));
    let cc = std::env::var("CC").unwrap_or_else(|_| "cc".into());
    let out = Command::new(&cc)
        .args(["-std=c99", "-O2", "-shared", "-fPIC", "-o"])
        .arg(&binary)
        .arg(build.join(format!("{id}.c")))
        .arg(build.join("fmi2.c"))
        .arg("-lm")
        .output()
        .with_context(|| format!("--fmu: running the C compiler `{cc}` (set CC to choose one)"))?;
    if !out.status.success() {
        bail!(
            "--fmu: the C compiler failed:\n{}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    let so = std::fs::read(&binary).with_context(|| format!("reading {}", binary.display()))?;
    let mut zip = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
    let stored = zip::write::SimpleFileOptions::default().compression_method(Compression::Stored);
    let mut entries: Vec<(String, Vec<u8>, u32)> = vec![
        (
            "modelDescription.xml".into(),
            model_description(lib).into_bytes(),
            0o644,
        ),
        (format!("binaries/{folder}/{id}.{suffix}"), so, 0o755),
    ];
    for (name, text) in files {
        entries.push((format!("sources/{name}"), text.into_bytes(), 0o644));
    }
    for (name, bytes, mode) in entries {
        zip.start_file(name, stored.unix_permissions(mode))?;
        zip.write_all(&bytes)?;
    }
    let bytes = zip.finish()?.into_inner();
    eomgen::atomic_write::write_atomic(fmu, &bytes)
        .with_context(|| format!("writing {}", fmu.display()))
}

/// modelDescription.xml: the states, their derivatives, the outputs, then
/// the parameters (inputs among them), in value-reference order.
fn model_description(lib: &Library) -> String {
    let info = &lib.tapes.info;
    let (n, nx, nout) = (info.dof(), lib.nx(), OUTPUT_NAMES.len());
    let mut vars = String::new();
    let mut var = |name: &str, vr: usize, attrs: &str, real: &str| {
        let _ = writeln!(
            vars,
            "    <ScalarVariable name=\"{}\" valueReference=\"{vr}\" {attrs}><Real{real}/></ScalarVariable>",
            xml(name)
        );
    };
    // A viscoelastic model's relaxed forces as trajectory.csv names them.
    let state = |k: usize| match k {
        k if k < n => format!("q.{}", info.coordinates[k]),
        k if k < 2 * n => format!("qd.{}", info.coordinates[k - n]),
        k => format!(
            "relaxed{}.{}",
            (k - 2 * n) / n,
            info.coordinates[(k - 2 * n) % n]
        ),
    };
    for k in 0..nx {
        var(
            &state(k),
            k,
            "causality=\"local\" variability=\"continuous\" initial=\"exact\"",
            " start=\"0\"",
        );
    }
    for k in 0..nx {
        let derivative = format!(" derivative=\"{}\"", k + 1);
        var(
            &format!("der({})", state(k)),
            nx + k,
            "causality=\"local\" variability=\"continuous\"",
            &derivative,
        );
    }
    for (k, name) in OUTPUT_NAMES.iter().enumerate() {
        var(
            name,
            2 * nx + k,
            "causality=\"output\" variability=\"continuous\"",
            "",
        );
    }
    for (k, name) in info.parameters.iter().enumerate() {
        let start = format!(
            " start=\"{}\"",
            literal(lib.values[k]).trim_matches(['(', ')'])
        );
        let attrs = match lib.inputs.iter().any(|(i, _)| *i == k) {
            true => "causality=\"input\" variability=\"continuous\"",
            false => "causality=\"parameter\" variability=\"fixed\" initial=\"exact\"",
        };
        var(name, 2 * nx + nout + k, attrs, &start);
    }
    let unknowns = |range: std::ops::Range<usize>| -> String {
        range
            .map(|i| format!("      <Unknown index=\"{}\"/>\n", i + 1))
            .collect()
    };
    let (derivatives, outputs) = (unknowns(nx..2 * nx), unknowns(2 * nx..2 * nx + nout));
    format!(
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n\
         <fmiModelDescription fmiVersion=\"2.0\" modelName=\"{model}\" guid=\"{{{hash}}}\" \
         description=\"softarm model {model}: the equations of motion by the TMT method\" \
         generationTool=\"softarm {version}\" variableNamingConvention=\"flat\" numberOfEventIndicators=\"{events}\">\n  \
         <ModelExchange modelIdentifier=\"{id}\" canGetAndSetFMUstate=\"false\" \
         canSerializeFMUstate=\"false\" providesDirectionalDerivative=\"false\">\n    \
         <SourceFiles>\n      <File name=\"{id}.c\"/>\n      <File name=\"fmi2.c\"/>\n    </SourceFiles>\n  \
         </ModelExchange>\n  <DefaultExperiment startTime=\"0\" stopTime=\"5\" tolerance=\"1e-06\"/>\n  \
         <ModelVariables>\n{vars}  </ModelVariables>\n  <ModelStructure>\n    \
         <Outputs>\n{outputs}    </Outputs>\n    <Derivatives>\n{derivatives}    </Derivatives>\n    \
         <InitialUnknowns>\n{derivatives}{outputs}    </InitialUnknowns>\n  </ModelStructure>\n\
         </fmiModelDescription>\n",
        model = xml(lib.model),
        hash = lib.hash,
        events = lib.contact_pairs(),
        version = env!("CARGO_PKG_VERSION"),
        id = lib.prefix,
    )
}
