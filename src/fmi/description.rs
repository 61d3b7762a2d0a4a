//! `modelDescription.xml` for FMI 2.0 and 3.0, generated from the variable table.

use std::fmt::Write;

use super::{MODEL_IDENTIFIER, fmi2_scalars, guid};
use crate::cosim::variables::unit_exponents;
use crate::cosim::{Causality, Component, VarType, Variability, Variable};

/// FMI version of a description.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FmiVersion {
    /// FMI 2.0.
    Two,
    /// FMI 3.0.
    Three,
}

fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
        .replace('\'', "&apos;")
}

fn causality(v: &Variable) -> &'static str {
    match v.causality {
        Causality::Parameter => "parameter",
        Causality::Input => "input",
        Causality::Output => "output",
        Causality::Independent => "independent",
    }
}

fn variability(v: &Variable) -> &'static str {
    match v.variability {
        Variability::Fixed => "fixed",
        Variability::Continuous if v.ty == VarType::Real => "continuous",
        _ => "discrete",
    }
}

/// `initial` attribute: parameters and inputs have exact start values, outputs are
/// calculated, time has none.
fn initial(v: &Variable) -> Option<&'static str> {
    match v.causality {
        Causality::Parameter => Some("exact"),
        Causality::Output => Some("calculated"),
        _ => None,
    }
}

/// Start values of a variable (parameters and inputs), from the instantiated
/// component.
fn start(c: &Component, var: usize) -> Option<Vec<String>> {
    let v = &c.variables()[var];
    if !matches!(v.causality, Causality::Parameter | Causality::Input) {
        return None;
    }
    let refs: Vec<_> = (0..v.size)
        .map(|element| crate::cosim::VarRef { var, element })
        .collect();
    Some(match v.ty {
        VarType::Real => {
            let mut x = vec![0.0; v.size];
            c.get_real(&refs, &mut x).ok()?;
            x.iter().map(|x| format!("{x:?}")).collect()
        }
        VarType::Integer => {
            let mut x = vec![0; v.size];
            c.get_integer(&refs, &mut x).ok()?;
            x.iter().map(|x| x.to_string()).collect()
        }
        VarType::String => c.get_string(&refs).ok()?,
    })
}

fn header(out: &mut String, c: &Component, model: &str, version: FmiVersion) {
    let scene = c.scene();
    let token = guid(c.fingerprint());
    let (fmi, id_attr) = match version {
        FmiVersion::Two => ("2.0", "guid"),
        FmiVersion::Three => ("3.0", "instantiationToken"),
    };
    let _ = writeln!(out, r#"<?xml version="1.0" encoding="UTF-8"?>"#);
    let _ = writeln!(
        out,
        r#"<fmiModelDescription fmiVersion="{fmi}" modelName="talus {}" {id_attr}="{token}" description="talus DEM scene '{}' as a co-simulation component" generationTool="talus {}" variableNamingConvention="structured"{}>"#,
        escape(model),
        escape(model),
        env!("CARGO_PKG_VERSION"),
        if version == FmiVersion::Two {
            r#" numberOfEventIndicators="0""#
        } else {
            ""
        }
    );
    match version {
        FmiVersion::Two => {
            let _ = writeln!(
                out,
                r#"  <CoSimulation modelIdentifier="{MODEL_IDENTIFIER}" canHandleVariableCommunicationStepSize="true" canGetAndSetFMUstate="true" canSerializeFMUstate="true" canInterpolateInputs="false" maxOutputDerivativeOrder="0" canBeInstantiatedOnlyOncePerProcess="false" needsExecutionTool="false"/>"#
            );
        }
        FmiVersion::Three => {
            let _ = writeln!(
                out,
                r#"  <CoSimulation modelIdentifier="{MODEL_IDENTIFIER}" canHandleVariableCommunicationStepSize="true" canGetAndSetFMUState="true" canSerializeFMUState="true" providesIntermediateUpdate="false" canReturnEarlyAfterIntermediateUpdate="false" hasEventMode="false"/>"#
            );
        }
    }
    let mut units: Vec<&str> = c.variables().iter().filter_map(|v| v.unit).collect();
    units.sort();
    units.dedup();
    let _ = writeln!(out, "  <UnitDefinitions>");
    for u in units {
        let e = unit_exponents(u);
        let mut base = String::new();
        for (name, x) in ["kg", "m", "s", "rad"].iter().zip(e) {
            if x != 0 {
                let _ = write!(base, r#" {name}="{x}""#);
            }
        }
        let _ = writeln!(
            out,
            r#"    <Unit name="{}"><BaseUnit{base}/></Unit>"#,
            escape(u)
        );
    }
    let _ = writeln!(out, "  </UnitDefinitions>");
    let _ = writeln!(out, "  <LogCategories>");
    let _ = writeln!(
        out,
        r#"    <Category name="logStatusError" description="Refused calls and failures"/>"#
    );
    let _ = writeln!(
        out,
        r#"    <Category name="logStatusWarning" description="Settings a user should check (a time step above the suggested one)"/>"#
    );
    let _ = writeln!(
        out,
        r#"    <Category name="logEvents" description="Life-cycle events"/>"#
    );
    let _ = writeln!(out, "  </LogCategories>");
    let _ = writeln!(
        out,
        r#"  <DefaultExperiment startTime="0.0" stopTime="{:?}" stepSize="{:?}"/>"#,
        scene.spec.simulation.end_time,
        (scene.dt * 100.0).max(1e-4)
    );
}

fn attributes(v: &Variable, vr: usize, name: &str) -> String {
    let mut a = format!(
        r#"name="{}" valueReference="{vr}" causality="{}" variability="{}""#,
        escape(name),
        causality(v),
        variability(v)
    );
    if let Some(i) = initial(v) {
        let _ = write!(a, r#" initial="{i}""#);
    }
    if !v.description.is_empty() {
        let _ = write!(a, r#" description="{}""#, escape(&v.description));
    }
    a
}

/// The FMI 2.0 description: vectors as scalars `name[k]`, mesh arrays left out.
pub fn fmi2(c: &Component, model: &str) -> String {
    let mut out = String::new();
    header(&mut out, c, model, FmiVersion::Two);
    let _ = writeln!(out, "  <ModelVariables>");
    let scalars = fmi2_scalars(c.variables());
    let mut outputs = Vec::new();
    // Each variable's start values once, not once per element (a fluid grid's
    // velocity has thousands).
    let mut starts: (usize, Option<Vec<String>>) = (usize::MAX, None);
    for (vr, (r, name)) in scalars.iter().enumerate() {
        let v = &c.variables()[r.var];
        if starts.0 != r.var {
            starts = (r.var, start(c, r.var));
        }
        let start = starts.1.as_ref().map(|s| s[r.element].clone());
        let _ = write!(out, "    <ScalarVariable {}>", attributes(v, vr, name));
        let ty = match v.ty {
            VarType::Real => "Real",
            VarType::Integer => "Integer",
            VarType::String => "String",
        };
        let mut element = format!("<{ty}");
        if let Some(u) = v.unit {
            let _ = write!(element, r#" unit="{}""#, escape(u));
        }
        if let Some(s) = start {
            let _ = write!(element, r#" start="{}""#, escape(&s));
        }
        let _ = writeln!(out, "{element}/></ScalarVariable>");
        if v.causality == Causality::Output {
            outputs.push(vr + 1);
        }
    }
    let _ = writeln!(out, "  </ModelVariables>");
    let _ = writeln!(out, "  <ModelStructure>");
    for section in ["Outputs", "InitialUnknowns"] {
        let _ = writeln!(out, "    <{section}>");
        for index in &outputs {
            let _ = writeln!(out, r#"      <Unknown index="{index}"/>"#);
        }
        let _ = writeln!(out, "    </{section}>");
    }
    let _ = writeln!(out, "  </ModelStructure>");
    let _ = writeln!(out, "</fmiModelDescription>");
    out
}

/// The FMI 3.0 description: vectors and mesh arrays as arrays.
pub fn fmi3(c: &Component, model: &str) -> String {
    let mut out = String::new();
    header(&mut out, c, model, FmiVersion::Three);
    let _ = writeln!(out, "  <ModelVariables>");
    let mut outputs = Vec::new();
    for (vr, v) in c.variables().iter().enumerate() {
        let ty = match v.ty {
            VarType::Real => "Float64",
            VarType::Integer => "Int32",
            VarType::String => "String",
        };
        let mut a = attributes(v, vr, &v.name);
        if let Some(u) = v.unit {
            let _ = write!(a, r#" unit="{}""#, escape(u));
        }
        let starts = start(c, vr);
        let mut children = String::new();
        match (&starts, v.ty) {
            (Some(s), VarType::String) => {
                for x in s {
                    let _ = write!(children, r#"<Start value="{}"/>"#, escape(x));
                }
            }
            (Some(s), _) => {
                let _ = write!(a, r#" start="{}""#, s.join(" "));
            }
            _ => {}
        }
        if v.size > 1 || v.array_only {
            let _ = write!(children, r#"<Dimension start="{}"/>"#, v.size);
        }
        if children.is_empty() {
            let _ = writeln!(out, "    <{ty} {a}/>");
        } else {
            let _ = writeln!(out, "    <{ty} {a}>{children}</{ty}>");
        }
        if v.causality == Causality::Output {
            outputs.push(vr);
        }
    }
    let _ = writeln!(out, "  </ModelVariables>");
    let _ = writeln!(out, "  <ModelStructure>");
    for vr in &outputs {
        let _ = writeln!(out, r#"    <Output valueReference="{vr}"/>"#);
    }
    for vr in &outputs {
        let _ = writeln!(out, r#"    <InitialUnknown valueReference="{vr}"/>"#);
    }
    let _ = writeln!(out, "  </ModelStructure>");
    let _ = writeln!(out, "</fmiModelDescription>");
    out
}
