//! `cdyn fmu`: a scenario as an FMI 2.0 co-simulation FMU — a ZIP of
//! `modelDescription.xml`, `binaries/linux64/NAME.so` (the shared library
//! of crates/cdyn-capi, one for every scenario, copied) and `resources/`
//! with the scenario (`scenario.toml`) and the URDF file it names, which
//! the library reads when it is instantiated. Written atomically: a
//! scenario that does not run gives `cdyn run`'s error and no file.

use crate::export::variables::{Causality, Variable, guid, load, urdf_path};
use crate::export::zip::Zip;
use anyhow::{Context, Result, anyhow, bail};
use std::fmt::Write;
use std::path::{Path, PathBuf};

/// The scenario's name inside `resources/`.
pub const SCENARIO_RESOURCE: &str = "scenario.toml";

/// The file name of the shared library on this platform.
pub const LIBRARY: &str = "libcdyn_capi.so";

/// The environment variable naming the shared library.
pub const LIBRARY_VARIABLE: &str = "CDYN_FMU_LIBRARY";

/// The shared library an FMU carries: `explicit`, else `$CDYN_FMU_LIBRARY`,
/// else [`LIBRARY`] beside the running executable.
pub fn find_library(explicit: Option<&Path>) -> Result<PathBuf> {
    let beside = std::env::current_exe().ok().and_then(|e| e.parent().map(|d| d.join(LIBRARY)));
    let chosen = explicit.map(Path::to_path_buf).or_else(|| std::env::var_os(LIBRARY_VARIABLE).map(PathBuf::from));
    match (chosen, beside) {
        (Some(path), _) if path.is_file() => Ok(path),
        (Some(path), _) => bail!("the FMU library {} does not exist", path.display()),
        (None, Some(path)) if path.is_file() => Ok(path),
        (None, beside) => bail!(
            "no {LIBRARY} beside the cdyn executable{}: build it with `cargo build -p cdyn-capi` (the profile of cdyn, e.g. --release), or name it with --library or {LIBRARY_VARIABLE}",
            beside.map_or(String::new(), |p| format!(" ({})", p.display()))
        ),
    }
}

/// XML text with `&`, `<`, `>` and `"` escaped.
fn xml(text: &str) -> String {
    text.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

/// `modelDescription.xml` of the FMU `name` of a scenario with these
/// variables (value references 0, 1, … in order), step `h` and end time `t_end`.
pub fn model_description(name: &str, guid: &str, h: f64, t_end: f64, variables: &[Variable]) -> String {
    let mut out = String::new();
    let _ = writeln!(out, r#"<?xml version="1.0" encoding="UTF-8"?>"#);
    let _ = writeln!(
        out,
        r#"<fmiModelDescription fmiVersion="2.0" modelName="{n}" guid="{guid}" description="cdyn scenario {n}: constrained multibody dynamics (CVSGF), fixed step h = {h}" generationTool="cdyn {v}" variableNamingConvention="flat" numberOfEventIndicators="0">"#,
        n = xml(name),
        v = env!("CARGO_PKG_VERSION"),
    );
    let _ = writeln!(
        out,
        r#"  <CoSimulation modelIdentifier="{}" needsExecutionTool="false" canHandleVariableCommunicationStepSize="false" canInterpolateInputs="false" maxOutputDerivativeOrder="0" canRunAsynchronuously="false" canBeInstantiatedOnlyOncePerProcess="false" canNotUseMemoryManagementFunctions="true" canGetAndSetFMUstate="true" canSerializeFMUstate="false" providesDirectionalDerivative="false"/>"#,
        xml(name)
    );
    let _ = writeln!(out, r#"  <LogCategories>"#);
    let _ =
        writeln!(out, r#"    <Category name="logStatusError" description="Errors: a refused call, a failed step"/>"#);
    let _ = writeln!(out, r#"  </LogCategories>"#);
    let _ = writeln!(out, r#"  <DefaultExperiment startTime="0.0" stopTime="{t_end:?}" stepSize="{h:?}"/>"#);
    let _ = writeln!(out, r#"  <ModelVariables>"#);
    for (vr, v) in variables.iter().enumerate() {
        let (causality, variability, initial, what) = match v.causality {
            Causality::Parameter => {
                ("parameter", "fixed", r#" initial="exact""#, "a scenario key, set before initialization")
            }
            Causality::Input => {
                ("input", "continuous", "", "an input of the scenario, held over each communication step")
            }
            Causality::Output => ("output", "continuous", r#" initial="calculated""#, "a CSV column of cdyn run"),
        };
        let start = v.start.map_or(String::new(), |s| format!(r#" start="{s:?}""#));
        let _ = writeln!(
            out,
            r#"    <ScalarVariable name="{}" valueReference="{vr}" description="{what}" causality="{causality}" variability="{variability}"{initial}>"#,
            xml(&v.name)
        );
        let _ = writeln!(out, r#"      <Real{start}/>"#);
        let _ = writeln!(out, r#"    </ScalarVariable>"#);
    }
    let _ = writeln!(out, r#"  </ModelVariables>"#);
    let outputs: Vec<usize> =
        variables.iter().enumerate().filter(|(_, v)| v.causality == Causality::Output).map(|(i, _)| i + 1).collect();
    let _ = writeln!(out, r#"  <ModelStructure>"#);
    for list in ["Outputs", "InitialUnknowns"] {
        let _ = writeln!(out, r#"    <{list}>"#);
        for i in &outputs {
            let _ = writeln!(out, r#"      <Unknown index="{i}"/>"#);
        }
        let _ = writeln!(out, r#"    </{list}>"#);
    }
    let _ = writeln!(out, r#"  </ModelStructure>"#);
    let _ = writeln!(out, r#"</fmiModelDescription>"#);
    out
}

/// Writes the FMU of the scenario at `scenario` to `out` (`NAME.fmu`, NAME
/// a C identifier: the model identifier), carrying `library` (see
/// [`find_library`]), once the scenario is read and its case built.
pub fn write(scenario: &Path, out: &Path, library: Option<&Path>) -> Result<()> {
    let name = out
        .file_stem()
        .and_then(|s| s.to_str())
        .filter(|_| out.extension().is_some_and(|e| e == "fmu"))
        .ok_or_else(|| anyhow!("--out {}: expected NAME.fmu", out.display()))?;
    let identifier =
        name.chars().enumerate().all(|(i, c)| c == '_' || c.is_ascii_alphabetic() || i > 0 && c.is_ascii_digit());
    if !identifier {
        bail!(
            "--out {}: the FMU's name {name:?} is its model identifier: use letters, digits and '_', not first a digit",
            out.display()
        );
    }
    let text = crate::case::scenario::read_bounded(scenario)?;
    let (parsed, table, _live, variables) = load(&text, scenario)?;
    let mut zip = Zip::default();
    let mut add = |inside: &str, bytes: &[u8]| zip.add(inside, bytes).with_context(|| format!("cannot pack {inside}"));
    let urdf = match urdf_path(&table, scenario) {
        Some(path) => {
            let relative = table["model"]["urdf"].as_str().unwrap_or_default();
            if Path::new(relative).components().any(|c| !matches!(c, std::path::Component::Normal(_))) {
                bail!(
                    "{}: [model] urdf = {relative:?}: an FMU carries the URDF file beside the scenario or below its folder",
                    scenario.display()
                );
            }
            let urdf = crate::case::scenario::read_bounded(&path)?;
            add(&format!("resources/{relative}"), urdf.as_bytes())?;
            Some(urdf)
        }
        None => None,
    };
    let library = find_library(library)?;
    let binary =
        std::fs::read(&library).with_context(|| format!("cannot read the FMU library {}", library.display()))?;
    let description = model_description(
        name,
        &guid(&table, urdf.as_deref()),
        parsed.integrator.h,
        parsed.integrator.t_end,
        &variables,
    );
    add("modelDescription.xml", description.as_bytes())?;
    add(&format!("resources/{SCENARIO_RESOURCE}"), text.as_bytes())?;
    add(&format!("binaries/linux64/{name}.so"), &binary)?;
    crate::io::output::write(out, &zip.finish())
}
