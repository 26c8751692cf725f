//! `softarm export MODEL --mex DIR`: the C library with a MATLAB/Octave
//! gateway (one MEX function named by its first argument), an `.m`
//! wrapper a function and `<model>_build.m`, which compiles it with
//! MATLAB's `mex` or Octave's `mkoctfile --mex`.

use std::path::{Path, PathBuf};

use anyhow::Result;

use super::c_api::Library;

/// The gateway, the same for every model but its names.
const GATEWAY: &str = include_str!("mex.c");

/// The wrappers: (function, arguments, what it returns).
const WRAPPERS: [(&str, &str, &str); 5] = [
    ("state_derivative", "t, x", "dx = f(t, x), x = [q; qd]"),
    (
        "jacobian",
        "t, x",
        "df/dx, 2n x 2n (with joints by central differences)",
    ),
    ("mass", "t, q", "the mass matrix M(q), n x n"),
    ("bias", "t, q, qd", "the bias h(t, q, qd): M qdd + h = 0"),
    (
        "outputs",
        "t, q, qd",
        "tip x, y, z (m), kinetic and potential energy (J), tip quaternion",
    ),
];

/// Write the library, the gateway and the `.m` files into `dir`; the
/// files written.
pub fn write(lib: &Library, dir: &Path) -> Result<Vec<PathBuf>> {
    let p = lib.prefix;
    let gateway = lib.named(GATEWAY);
    let mut files = vec![
        (format!("{p}.h"), lib.header()),
        (format!("{p}.c"), lib.source()),
        (format!("{p}_mex.c"), gateway),
        (format!("{p}_build.m"), build_script(p)),
    ];
    let contact = [
        (
            "contact",
            "t, x",
            "each contact pair's gap (m); [gap, normal] also its normal force (N)",
        ),
        (
            "contact_update",
            "t, x",
            "bring the contact records up to x: call it after each accepted step",
        ),
    ];
    let contact = &contact[..2 * usize::from(lib.contact_pairs() > 0)];
    for &(name, args, what) in WRAPPERS.iter().chain(contact) {
        // One output, two (contact's) or none (contact_update's).
        let (returns, call) = match name {
            "contact_update" => ("", ""),
            "contact" => ("[gap, normal] = ", "[gap, normal] = "),
            _ => ("out = ", "out = "),
        };
        let text = format!(
            "function {returns}{p}_{name}({args})\n\
             %{upn}  {what}: softarm model {model}.\n\
             %   Compile once with {p}_build. See docs/export.md in softarm.\n\
             {call}{p}_mex('{name}', {args});\nend\n",
            upn = format!("{p}_{name}").to_ascii_uppercase(),
            model = lib.model,
        );
        files.push((format!("{p}_{name}.m"), text));
    }
    super::write_set(dir, &files)
}

/// `<model>_build.m`: the MEX function from its two sources, by Octave's
/// mkoctfile or MATLAB's mex (the separate-complex API, which both read).
fn build_script(p: &str) -> String {
    format!(
        "function {p}_build()\n\
         %{up}_BUILD  Compile {p}_mex from {p}_mex.c and {p}.c (Octave or MATLAB).\n\
         here = fileparts(mfilename('fullpath'));\n\
         sources = {{fullfile(here, '{p}_mex.c'), fullfile(here, '{p}.c')}};\n\
         if exist('OCTAVE_VERSION', 'builtin')\n  \
         mkoctfile('--mex', '-O2', '-o', fullfile(here, '{p}_mex'), sources{{:}});\n\
         else\n  \
         mex('-R2017b', '-O', '-outdir', here, '-output', '{p}_mex', sources{{:}});\n\
         end\nend\n",
        up = p.to_ascii_uppercase()
    )
}
