//! System descriptions of the closed loop for other masters: `cargo xtask ssp`.
//!
//! Generated from the modelDescription.xml of the packaged FMUs, with the connections
//! discovered by name exactly as `masters/closed_loop.py` discovers them: every controller
//! input takes the plant output of the same name, every plant input takes the controller
//! output of the same name; an input without an output of its name, or of another type, stops
//! the generation. No connection is listed by hand.
//!
//! - `systems/towing.ssp`: SSP 1.0 (`SystemStructure.ssd`, `resources/<Model>.fmu`), for
//!   fmpy's `simulate_ssp` and libcosim. A build product holding both binaries: gitignored,
//!   rebuilt by every run.
//! - `systems/fmu/<Model>.fmu`: copies of the packaged FMUs, referenced by
//!   `OspSystemStructure.xml` as `fmu/<Model>.fmu`, so the committed file works from the
//!   repository whatever `CARGO_TARGET_DIR` is. Gitignored.
//! - `systems/OspSystemStructure.xml` and `systems/<Model>_OspModelDescription.xml` (OSP
//!   interface specification 1.0 variable groups): text, committed. A run fails when the
//!   committed files differ from the generated ones; `cargo xtask ssp --update` rewrites them.
//!
//! docs/masters.md describes the files and how each master runs them.

use crate::{fail, fmu, progress, root, Result};
use std::collections::{BTreeMap, BTreeSet};
use std::io::{Read as _, Write as _};
use std::path::{Path, PathBuf};
use zip::write::SimpleFileOptions;

/// Instance names of the FMUs in every system description, as in `masters/closed_loop.py`.
pub const INSTANCES: [(&str, &str); 2] =
    [("plant", "TowingPlant"), ("controller", "TowingController")];

/// Namespace and version of the OSP interface specification's model description.
const OSP_MD_NAMESPACE: &str = "https://open-simulation-platform.com/OspModelDescription/1.0.0";
/// Namespace of libcosim's OspSystemStructure.xml (schema version 0.1).
const OSP_SS_NAMESPACE: &str = "http://opensimulationplatform.com/MSMI/OSPSystemStructure";

/// `cargo xtask ssp [--update]`.
pub fn run(args: &[String]) -> Result<()> {
    const STEP: &str = "ssp";
    let update = match args {
        [] => false,
        [flag] if flag == "--update" => true,
        other => {
            return fail(
                STEP,
                format!("unexpected arguments {other:?}; usage: cargo xtask ssp [--update]"),
            )
        }
    };
    let packaged = fmu::package_all()?;
    let mut models = Vec::new();
    for (instance, model) in INSTANCES {
        let path = packaged
            .iter()
            .find(|p| {
                p.file_name()
                    .is_some_and(|n| n == format!("{model}.fmu").as_str())
            })
            .cloned()
            .ok_or_else(|| crate::StepError {
                step: STEP.into(),
                reason: format!("{model}.fmu was not packaged"),
            })?;
        let xml = read_model_description(&path).or_else(|e| fail(STEP, e))?;
        let description = parse_model_description(&xml).or_else(|e| {
            fail(
                STEP,
                format!("{}: modelDescription.xml: {e}", path.display()),
            )
        })?;
        models.push(Model {
            instance: instance.to_owned(),
            path,
            description,
        });
    }
    let generated = generate(&models).or_else(|e| fail(STEP, e))?;

    let dir = systems_dir();
    let fmu_dir = dir.join("fmu");
    std::fs::create_dir_all(&fmu_dir)
        .or_else(|e| fail(STEP, format!("cannot create {}: {e}", fmu_dir.display())))?;
    let mut ssp_entries = vec![(
        "SystemStructure.ssd".to_owned(),
        generated.ssd.clone().into_bytes(),
    )];
    for m in &models {
        let bytes = std::fs::read(&m.path)
            .or_else(|e| fail(STEP, format!("cannot read {}: {e}", m.path.display())))?;
        let name = format!("{}.fmu", m.description.model_identifier);
        write_atomically(&fmu_dir.join(&name), &bytes).or_else(|e| fail(STEP, e))?;
        ssp_entries.push((format!("resources/{name}"), bytes));
    }
    progress(&format!("copied the FMUs to {}", fmu_dir.display()));
    let ssp = dir.join("towing.ssp");
    write_zip(&ssp, &ssp_entries).or_else(|e| fail(STEP, e))?;
    progress(&format!("wrote {}", ssp.display()));

    if update {
        for (name, text) in &generated.committed {
            let path = dir.join(name);
            std::fs::write(&path, text)
                .or_else(|e| fail(STEP, format!("cannot write {}: {e}", path.display())))?;
            progress(&format!("wrote {}", path.display()));
        }
    }
    let stale = stale_files(&dir, &generated.committed);
    if !stale.is_empty() {
        return fail(
            STEP,
            format!(
                "committed files differ from the ones generated from the packaged modelDescriptions: {}; \
                 run `cargo xtask ssp --update` and commit the result",
                stale.join(", ")
            ),
        );
    }
    progress(&format!(
        "OSP files up to date: {}",
        generated
            .committed
            .iter()
            .map(|(n, _)| dir.join(n).display().to_string())
            .collect::<Vec<_>>()
            .join(", ")
    ));
    Ok(())
}

/// The files of `committed` (name in `dir`, expected text) that are missing or differ.
fn stale_files(dir: &Path, committed: &[(String, String)]) -> Vec<String> {
    committed
        .iter()
        .map(|(name, _)| dir.join(name))
        .zip(committed)
        .filter(|(path, (_, text))| {
            std::fs::read_to_string(path).ok().as_deref() != Some(text.as_str())
        })
        .map(|(path, _)| path.display().to_string())
        .collect()
}

/// The `systems/` directory of the repository.
pub fn systems_dir() -> PathBuf {
    root().join("systems")
}

// --------------------------------------------------------------------------- model descriptions

/// One FMU of the system: its instance name, packaged file and parsed modelDescription.
#[derive(Debug, Clone)]
pub struct Model {
    pub instance: String,
    pub path: PathBuf,
    pub description: ModelDescription,
}

/// What the system descriptions need from a modelDescription.xml.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ModelDescription {
    pub model_name: String,
    pub model_identifier: String,
    /// `DefaultExperiment stepSize`, as written.
    pub step_size: Option<String>,
    /// `UnitDefinitions`: name and `BaseUnit` attributes.
    pub units: Vec<(String, Vec<(String, String)>)>,
    pub variables: Vec<Variable>,
}

/// One `ScalarVariable`.
#[derive(Debug, Clone, PartialEq)]
pub struct Variable {
    pub name: String,
    pub causality: String,
    /// `Real`, `Integer`, `Boolean`, `String` or `Enumeration`.
    pub type_name: String,
    /// The variable's unit, or that of its declared type.
    pub unit: Option<String>,
}

impl Variable {
    /// Type as connected: an Enumeration is transferred as an Integer (as the master does).
    fn base_type(&self) -> &str {
        if self.type_name == "Enumeration" {
            "Integer"
        } else {
            &self.type_name
        }
    }
}

fn read_model_description(fmu: &Path) -> std::result::Result<String, String> {
    let file = std::fs::File::open(fmu).map_err(|e| format!("{}: {e}", fmu.display()))?;
    let mut archive = zip::ZipArchive::new(file).map_err(|e| format!("{}: {e}", fmu.display()))?;
    let mut entry = archive
        .by_name("modelDescription.xml")
        .map_err(|e| format!("{}: modelDescription.xml: {e}", fmu.display()))?;
    let mut xml = String::new();
    entry
        .read_to_string(&mut xml)
        .map_err(|e| format!("{}: modelDescription.xml: {e}", fmu.display()))?;
    Ok(xml)
}

/// The child elements of `node` named `name`.
fn children<'a, 'i>(
    node: roxmltree::Node<'a, 'i>,
    name: &'static str,
) -> impl Iterator<Item = roxmltree::Node<'a, 'i>> {
    node.children()
        .filter(move |c| c.is_element() && c.tag_name().name() == name)
}

/// The first child element of `node` named `name`.
fn child<'a, 'i>(
    node: roxmltree::Node<'a, 'i>,
    name: &'static str,
) -> Option<roxmltree::Node<'a, 'i>> {
    children(node, name).next()
}

/// The type element (`Real`, `Integer`, `Boolean`, `String`, `Enumeration`) of a
/// `ScalarVariable` or `SimpleType`.
fn type_element<'a, 'i>(node: roxmltree::Node<'a, 'i>) -> Option<roxmltree::Node<'a, 'i>> {
    const TYPES: [&str; 5] = ["Real", "Integer", "Boolean", "String", "Enumeration"];
    node.children()
        .find(|c| c.is_element() && TYPES.contains(&c.tag_name().name()))
}

/// Parses the parts of an FMI 2.0 modelDescription.xml the system descriptions use
/// (with `roxmltree`).
pub fn parse_model_description(xml: &str) -> std::result::Result<ModelDescription, String> {
    let doc = roxmltree::Document::parse(xml).map_err(|e| format!("not well-formed XML: {e}"))?;
    let root = doc.root_element();
    if root.tag_name().name() != "fmiModelDescription" {
        return Err(format!(
            "the root element is <{}>, not <fmiModelDescription>",
            root.tag_name().name()
        ));
    }
    let mut md = ModelDescription {
        model_name: root.attribute("modelName").unwrap_or_default().to_owned(),
        model_identifier: child(root, "CoSimulation")
            .and_then(|c| c.attribute("modelIdentifier"))
            .unwrap_or_default()
            .to_owned(),
        step_size: child(root, "DefaultExperiment")
            .and_then(|d| d.attribute("stepSize"))
            .map(str::to_owned),
        ..ModelDescription::default()
    };
    if let Some(defs) = child(root, "UnitDefinitions") {
        for unit in children(defs, "Unit") {
            let base = child(unit, "BaseUnit")
                .map(|b| {
                    b.attributes()
                        .map(|a| (a.name().to_owned(), a.value().to_owned()))
                        .collect()
                })
                .unwrap_or_default();
            md.units
                .push((unit.attribute("name").unwrap_or_default().to_owned(), base));
        }
    }
    let mut type_units: BTreeMap<&str, &str> = BTreeMap::new();
    if let Some(defs) = child(root, "TypeDefinitions") {
        for t in children(defs, "SimpleType") {
            if let (Some(name), Some(unit)) = (
                t.attribute("name"),
                type_element(t).and_then(|e| e.attribute("unit")),
            ) {
                type_units.insert(name, unit);
            }
        }
    }
    if let Some(vars) = child(root, "ModelVariables") {
        for v in children(vars, "ScalarVariable") {
            let name = v.attribute("name").ok_or("ScalarVariable without name")?;
            let ty = type_element(v)
                .ok_or_else(|| format!("ScalarVariable {name:?} has no type element"))?;
            let unit = ty.attribute("unit").or_else(|| {
                ty.attribute("declaredType")
                    .and_then(|d| type_units.get(d).copied())
            });
            md.variables.push(Variable {
                name: name.to_owned(),
                causality: v.attribute("causality").unwrap_or("local").to_owned(),
                type_name: ty.tag_name().name().to_owned(),
                unit: unit.map(str::to_owned),
            });
        }
    }
    if md.model_identifier.is_empty() {
        return Err("no CoSimulation modelIdentifier".into());
    }
    Ok(md)
}

fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

// --------------------------------------------------------------------------- connections

/// One connection: the output `name` of instance `from` feeds the input `name` of `to`.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord)]
pub struct Link {
    pub from: usize,
    pub to: usize,
    pub name: String,
    pub base_type: String,
}

/// Connections by identical names between the first two models, as `masters/closed_loop.py`
/// makes them: every input of the controller (models[1]) from the plant (models[0]), then
/// every input of the plant from the controller, each in the receiver's modelDescription
/// order. Every input must find an output of its name and type; the error names all that
/// do not.
pub fn discover_links(models: &[&ModelDescription; 2]) -> std::result::Result<Vec<Link>, String> {
    let mut links = Vec::new();
    let mut problems = Vec::new();
    for (sender, receiver) in [(0, 1), (1, 0)] {
        let outputs: BTreeMap<&str, &Variable> = models[sender]
            .variables
            .iter()
            .filter(|v| v.causality == "output")
            .map(|v| (v.name.as_str(), v))
            .collect();
        let (rname, sname) = (INSTANCES[receiver].0, INSTANCES[sender].0);
        for input in models[receiver]
            .variables
            .iter()
            .filter(|v| v.causality == "input")
        {
            match outputs.get(input.name.as_str()) {
                None => problems.push(format!(
                    "{rname} input '{}' has no {sname} output of the same name",
                    input.name
                )),
                Some(out) if out.base_type() != input.base_type() => problems.push(format!(
                    "{rname} input '{}' is {} but the {sname} output of that name is {}",
                    input.name, input.type_name, out.type_name
                )),
                Some(_) if !matches!(input.base_type(), "Real" | "Integer" | "Boolean") => {
                    problems.push(format!(
                        "{rname} input '{}' has type {}, which the masters do not connect",
                        input.name, input.type_name
                    ));
                }
                Some(_) => links.push(Link {
                    from: sender,
                    to: receiver,
                    name: input.name.clone(),
                    base_type: input.base_type().to_owned(),
                }),
            }
        }
    }
    if problems.is_empty() {
        Ok(links)
    } else {
        Err(format!(
            "cannot connect the FMUs by name:\n  {}",
            problems.join("\n  ")
        ))
    }
}

// --------------------------------------------------------------------------- OSP variable groups

/// OSP-IS variable group types used here, in the order the schema's sequences require, with
/// the unit that selects them (the modelDescription's units of these FMUs).
const OSP_TYPES: [(&str, &str); 6] = [
    ("Force", "N"),
    ("Torque", "N.m"),
    ("LinearVelocity", "m/s"),
    ("AngularVelocity", "rad/s"),
    ("LinearDisplacement", "m"),
    ("AngularDisplacement", "rad"),
];
/// OSP-IS allows at most three variables in a typed group (a 3-vector).
const OSP_MAX_DIMENSION: usize = 3;

/// A typed OSP group inside a [`TopGroup`]: up to three consecutive variables of one object
/// with the same physical type.
#[derive(Debug, Clone, PartialEq)]
pub struct SubGroup {
    pub osp_type: &'static str,
    pub name: String,
    /// (variable name, unit)
    pub variables: Vec<(String, String)>,
}

/// A `Generic` OSP group: the inputs or the outputs of one object (the part of the variable
/// name before its last '.': `ship`, `tug1`, `towline2`, `obstacle[3]`, ...), named
/// `<object>.in` or `<object>.out`. Variables of a physical type form typed sub-groups named
/// `<object>.{<member>,...}`; the others (counts, flags, kinds) are direct members.
#[derive(Debug, Clone, PartialEq)]
pub struct TopGroup {
    pub object: String,
    pub causality: String,
    pub name: String,
    pub direct: Vec<String>,
    pub subgroups: Vec<SubGroup>,
}

impl TopGroup {
    /// Everything but the group's own name: equal shapes connect group to group.
    fn shape(&self) -> (Vec<&str>, Vec<(&str, Vec<&str>)>) {
        (
            self.direct.iter().map(String::as_str).collect(),
            self.subgroups
                .iter()
                .map(|s| {
                    (
                        s.osp_type,
                        s.variables.iter().map(|(n, _)| n.as_str()).collect(),
                    )
                })
                .collect(),
        )
    }
}

fn split_name(name: &str) -> (&str, &str) {
    match name.rfind('.') {
        Some(i) => (&name[..i], &name[i + 1..]),
        None => (name, name),
    }
}

fn osp_type(v: &Variable) -> Option<(usize, &'static str)> {
    if v.type_name != "Real" {
        return None;
    }
    let unit = v.unit.as_deref()?;
    OSP_TYPES
        .iter()
        .position(|(_, u)| *u == unit)
        .map(|i| (i, OSP_TYPES[i].0))
}

/// The OSP variable groups of one model: one `Generic` group per object and causality (inputs
/// and outputs only), in the order of first appearance in the modelDescription.
pub fn variable_groups(md: &ModelDescription) -> Vec<TopGroup> {
    let mut order: Vec<(String, String)> = Vec::new();
    let mut members: BTreeMap<(String, String), Vec<&Variable>> = BTreeMap::new();
    for v in md
        .variables
        .iter()
        .filter(|v| v.causality == "input" || v.causality == "output")
    {
        let key = (split_name(&v.name).0.to_owned(), v.causality.clone());
        if !members.contains_key(&key) {
            order.push(key.clone());
        }
        members.entry(key).or_default().push(v);
    }
    order
        .into_iter()
        .map(|key| {
            let vars = &members[&key];
            let (object, causality) = key;
            let mut direct = Vec::new();
            // Runs of consecutive variables of one type, cut into chunks of three.
            let mut runs: Vec<(usize, Vec<&Variable>)> = Vec::new();
            let mut previous: Option<usize> = None;
            for v in vars {
                match osp_type(v) {
                    None => {
                        direct.push(v.name.clone());
                        previous = None;
                    }
                    Some((t, _)) => {
                        match runs.last_mut() {
                            Some((rt, run))
                                if previous == Some(t)
                                    && *rt == t
                                    && run.len() < OSP_MAX_DIMENSION =>
                            {
                                run.push(v);
                            }
                            _ => runs.push((t, vec![v])),
                        }
                        previous = Some(t);
                    }
                }
            }
            // The schema orders a Generic group's children by type (stable within a type).
            runs.sort_by_key(|(t, _)| *t);
            let subgroups = runs
                .into_iter()
                .map(|(t, run)| SubGroup {
                    osp_type: OSP_TYPES[t].0,
                    name: format!(
                        "{object}.{{{}}}",
                        run.iter()
                            .map(|v| split_name(&v.name).1)
                            .collect::<Vec<_>>()
                            .join(",")
                    ),
                    variables: run
                        .iter()
                        .map(|v| (v.name.clone(), v.unit.clone().unwrap_or_default()))
                        .collect(),
                })
                .collect();
            let suffix = if causality == "input" { "in" } else { "out" };
            TopGroup {
                name: format!("{object}.{suffix}"),
                object,
                causality,
                direct,
                subgroups,
            }
        })
        .collect()
}

/// `<Model>_OspModelDescription.xml` (OSP-IS 1.0).
pub fn osp_model_description(md: &ModelDescription) -> String {
    let mut s = String::new();
    s.push_str("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    s.push_str(&format!(
        "<!-- OSP interface variable groups of {} (OSP-IS 1.0), generated by `cargo xtask ssp`\n     \
         from its modelDescription.xml; do not edit (docs/masters.md). One Generic group per object\n     \
         and causality (<object>.in, <object>.out), typed sub-groups <object>.{{<member>,...}}. -->\n",
        escape(&md.model_identifier)
    ));
    s.push_str(&format!(
        "<OspModelDescription xmlns=\"{OSP_MD_NAMESPACE}\" version=\"1.0\">\n  <VariableGroups>\n"
    ));
    for g in variable_groups(md) {
        s.push_str(&format!("    <Generic name=\"{}\">\n", escape(&g.name)));
        for v in &g.direct {
            s.push_str(&format!("      <Variable ref=\"{}\"/>\n", escape(v)));
        }
        for sub in &g.subgroups {
            s.push_str(&format!(
                "      <{} name=\"{}\">\n",
                sub.osp_type,
                escape(&sub.name)
            ));
            for (v, unit) in &sub.variables {
                s.push_str(&format!(
                    "        <Variable ref=\"{}\" unit=\"{}\"/>\n",
                    escape(v),
                    escape(unit)
                ));
            }
            s.push_str(&format!("      </{}>\n", sub.osp_type));
        }
        s.push_str("    </Generic>\n");
    }
    s.push_str("  </VariableGroups>\n</OspModelDescription>\n");
    s
}

/// A connection of the OSP system structure: group to group, or variable to variable;
/// endpoints (instance index, name), the sender first.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum OspConnection {
    Group((usize, String), (usize, String)),
    Variable((usize, String), (usize, String)),
}

/// The OSP connections realising `links`: the groups `<object>.out` of the sender and
/// `<object>.in` of the receiver connect as a whole when they have the same shape; else
/// every typed sub-group that both have connects, and the remaining links connect variable
/// by variable. The expansion equals `links` exactly (checked).
pub fn osp_connections(
    models: &[&ModelDescription; 2],
    links: &[Link],
) -> std::result::Result<Vec<OspConnection>, String> {
    let groups = [variable_groups(models[0]), variable_groups(models[1])];
    let mut pending: BTreeSet<(usize, usize, String)> = links
        .iter()
        .map(|l| (l.from, l.to, l.name.clone()))
        .collect();
    let mut connections = Vec::new();
    let mut covered = Vec::new();
    for (from, to) in [(0, 1), (1, 0)] {
        for rg in groups[to].iter().filter(|g| g.causality == "input") {
            let Some(sg) = groups[from]
                .iter()
                .find(|g| g.causality == "output" && g.object == rg.object)
            else {
                continue;
            };
            if sg.shape() == rg.shape() {
                connections.push(OspConnection::Group(
                    (from, sg.name.clone()),
                    (to, rg.name.clone()),
                ));
                covered.extend(rg.direct.iter().cloned().map(|n| (from, to, n)));
                for sub in &rg.subgroups {
                    covered.extend(sub.variables.iter().map(|(n, _)| (from, to, n.clone())));
                }
                continue;
            }
            for sub in &rg.subgroups {
                let same = sg.subgroups.iter().find(|s| {
                    s.osp_type == sub.osp_type
                        && s.variables
                            .iter()
                            .map(|(n, _)| n)
                            .eq(sub.variables.iter().map(|(n, _)| n))
                });
                if let Some(ss) = same {
                    connections.push(OspConnection::Group(
                        (from, ss.name.clone()),
                        (to, sub.name.clone()),
                    ));
                    covered.extend(sub.variables.iter().map(|(n, _)| (from, to, n.clone())));
                }
            }
        }
    }
    for c in &covered {
        if !pending.remove(c) {
            return Err(format!(
                "OSP group connection of {} -> {} '{}' is not a connection by name",
                INSTANCES[c.0].0, INSTANCES[c.1].0, c.2
            ));
        }
    }
    // The rest variable by variable, in the order of `links`.
    for l in links {
        if pending.remove(&(l.from, l.to, l.name.clone())) {
            connections.push(OspConnection::Variable(
                (l.from, l.name.clone()),
                (l.to, l.name.clone()),
            ));
        }
    }
    debug_assert!(pending.is_empty());
    Ok(connections)
}

/// The generated files: the SSD (goes into the .ssp) and the committed OSP files
/// (file name in `systems/`, text).
#[derive(Debug)]
pub struct Generated {
    pub ssd: String,
    pub committed: Vec<(String, String)>,
}

/// Generates every system file from the two models (plant first, controller second).
pub fn generate(models: &[Model]) -> std::result::Result<Generated, String> {
    let [plant, controller] = models else {
        return Err(format!("expected two models, got {}", models.len()));
    };
    let mds = [&plant.description, &controller.description];
    let links = discover_links(&mds)?;
    let step = common_step_size(&mds)?;
    let ssd = ssd(models, &links, &step)?;
    let osp = osp_connections(&mds, &links)?;
    let mut committed = vec![(
        "OspSystemStructure.xml".to_owned(),
        osp_system_structure(models, &osp, &step),
    )];
    for m in models {
        committed.push((
            format!("{}_OspModelDescription.xml", m.description.model_name),
            osp_model_description(&m.description),
        ));
    }
    Ok(Generated { ssd, committed })
}

/// The communication step of the system: the FMUs' common `DefaultExperiment stepSize`.
fn common_step_size(mds: &[&ModelDescription; 2]) -> std::result::Result<String, String> {
    let steps: Vec<f64> = mds
        .iter()
        .map(|md| {
            md.step_size
                .as_deref()
                .and_then(|s| s.parse::<f64>().ok())
                .filter(|h| *h > 0.0 && h.is_finite())
                .ok_or_else(|| {
                    format!(
                        "{} has no valid DefaultExperiment stepSize",
                        md.model_identifier
                    )
                })
        })
        .collect::<std::result::Result<_, _>>()?;
    if steps[0] != steps[1] {
        return Err(format!(
            "the FMUs recommend different steps ({} s and {} s)",
            steps[0], steps[1]
        ));
    }
    Ok(format!("{}", steps[0]))
}

fn osp_system_structure(models: &[Model], connections: &[OspConnection], step: &str) -> String {
    let mut s = String::new();
    s.push_str("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    s.push_str(
        "<!-- The closed loop for libcosim (Open Simulation Platform), generated by `cargo xtask ssp`\n     \
         from the modelDescription.xml of the packaged FMUs; do not edit (docs/masters.md).\n     \
         Connections by identical names, as masters/closed_loop.py makes them, written as OSP\n     \
         variable group connections where the groups of both sides match. The FMUs are the copies\n     \
         `cargo xtask ssp` puts in systems/fmu/. -->\n",
    );
    s.push_str(&format!(
        "<OspSystemStructure xmlns=\"{OSP_SS_NAMESPACE}\" version=\"0.1\">\n"
    ));
    s.push_str("  <StartTime>0.0</StartTime>\n");
    s.push_str(&format!("  <BaseStepSize>{step}</BaseStepSize>\n"));
    s.push_str("  <Algorithm>fixedStep</Algorithm>\n  <Simulators>\n");
    for m in models {
        s.push_str(&format!(
            "    <Simulator name=\"{}\" source=\"fmu/{}.fmu\" stepSize=\"{step}\"/>\n",
            escape(&m.instance),
            escape(&m.description.model_identifier)
        ));
    }
    s.push_str("  </Simulators>\n  <Connections>\n");
    let name = |i: usize| escape(&models[i].instance);
    // The schema wants every VariableConnection before the VariableGroupConnections.
    for c in connections {
        if let OspConnection::Variable((a, va), (b, vb)) = c {
            s.push_str(&format!(
                "    <VariableConnection>\n      <Variable simulator=\"{}\" name=\"{}\"/>\n      \
                 <Variable simulator=\"{}\" name=\"{}\"/>\n    </VariableConnection>\n",
                name(*a),
                escape(va),
                name(*b),
                escape(vb)
            ));
        }
    }
    for c in connections {
        if let OspConnection::Group((a, ga), (b, gb)) = c {
            s.push_str(&format!(
                "    <VariableGroupConnection>\n      <VariableGroup simulator=\"{}\" name=\"{}\"/>\n      \
                 <VariableGroup simulator=\"{}\" name=\"{}\"/>\n    </VariableGroupConnection>\n",
                name(*a),
                escape(ga),
                name(*b),
                escape(gb)
            ));
        }
    }
    s.push_str("  </Connections>\n</OspSystemStructure>\n");
    s
}

/// `SystemStructure.ssd` (SSP 1.0): both FMUs as components `resources/<Model>.fmu`, a
/// connector for every connected variable, the connections by name, the units, and a
/// default experiment with libcosim's fixed-step annotation (fmpy ignores annotations).
fn ssd(models: &[Model], links: &[Link], step: &str) -> std::result::Result<String, String> {
    let mut s = String::new();
    s.push_str("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    s.push_str(
        "<!-- The closed loop of TowingPlant and TowingController, generated by `cargo xtask ssp`\n     \
         from the modelDescription.xml of the packaged FMUs (docs/masters.md). Connections by\n     \
         identical names, as masters/closed_loop.py makes them. -->\n",
    );
    s.push_str(
        "<ssd:SystemStructureDescription \
         xmlns:ssc=\"http://ssp-standard.org/SSP1/SystemStructureCommon\" \
         xmlns:ssd=\"http://ssp-standard.org/SSP1/SystemStructureDescription\" \
         xmlns:osp=\"http://opensimulationplatform.com/SSP/OSPAnnotations\" \
         name=\"towing\" version=\"1.0\">\n",
    );
    s.push_str(
        "  <ssd:System name=\"towing\" description=\"A ship towed by two tugs (TowingPlant) under distributed MPC (TowingController)\">\n    <ssd:Elements>\n",
    );
    let mut used_units = BTreeSet::new();
    for (i, m) in models.iter().enumerate() {
        s.push_str(&format!(
            "      <ssd:Component name=\"{}\" source=\"resources/{}.fmu\" type=\"application/x-fmu-sharedlibrary\">\n        <ssd:Connectors>\n",
            escape(&m.instance),
            escape(&m.description.model_identifier)
        ));
        let connected: BTreeSet<&str> = links
            .iter()
            .filter(|l| l.from == i || l.to == i)
            .map(|l| l.name.as_str())
            .collect();
        for v in m.description.variables.iter().filter(|v| {
            (v.causality == "input" || v.causality == "output")
                && connected.contains(v.name.as_str())
        }) {
            let unit = match (&v.unit, v.base_type()) {
                (Some(u), "Real") => {
                    used_units.insert(u.clone());
                    format!(" unit=\"{}\"", escape(u))
                }
                _ => String::new(),
            };
            s.push_str(&format!(
                "          <ssd:Connector name=\"{}\" kind=\"{}\"><ssc:{}{unit}/></ssd:Connector>\n",
                escape(&v.name),
                v.causality,
                v.base_type()
            ));
        }
        s.push_str("        </ssd:Connectors>\n      </ssd:Component>\n");
    }
    s.push_str("    </ssd:Elements>\n    <ssd:Connections>\n");
    for l in links {
        s.push_str(&format!(
            "      <ssd:Connection startElement=\"{}\" startConnector=\"{}\" endElement=\"{}\" endConnector=\"{}\"/>\n",
            escape(&models[l.from].instance),
            escape(&l.name),
            escape(&models[l.to].instance),
            escape(&l.name)
        ));
    }
    s.push_str("    </ssd:Connections>\n  </ssd:System>\n");
    if !used_units.is_empty() {
        s.push_str("  <ssd:Units>\n");
        for unit in &used_units {
            let mut definitions = models.iter().filter_map(|m| {
                m.description
                    .units
                    .iter()
                    .find(|(n, _)| n == unit)
                    .map(|(_, b)| b)
            });
            let base = definitions
                .next()
                .ok_or_else(|| format!("unit {unit:?} is not defined in the modelDescriptions"))?;
            if definitions.any(|b| b != base) {
                return Err(format!("the FMUs define unit {unit:?} differently"));
            }
            let attrs: String = base
                .iter()
                .map(|(k, v)| format!(" {k}=\"{}\"", escape(v)))
                .collect();
            s.push_str(&format!(
                "    <ssc:Unit name=\"{}\"><ssc:BaseUnit{attrs}/></ssc:Unit>\n",
                escape(unit)
            ));
        }
        s.push_str("  </ssd:Units>\n");
    }
    s.push_str(&format!(
        "  <ssd:DefaultExperiment startTime=\"0\">\n    <ssd:Annotations>\n      \
         <ssc:Annotation type=\"com.opensimulationplatform\">\n        <osp:Algorithm><osp:FixedStepAlgorithm baseStepSize=\"{step}\"/></osp:Algorithm>\n      \
         </ssc:Annotation>\n    </ssd:Annotations>\n  </ssd:DefaultExperiment>\n"
    ));
    s.push_str("</ssd:SystemStructureDescription>\n");
    Ok(s)
}

// --------------------------------------------------------------------------- files

/// Writes through a temporary file of this process, so a master never sees a half-written
/// file and two runs at once do not take each other's file away.
fn write_atomically(path: &Path, bytes: &[u8]) -> std::result::Result<(), String> {
    let tmp = path.with_extension(format!("{}.tmp", std::process::id()));
    std::fs::write(&tmp, bytes).map_err(|e| format!("{}: {e}", tmp.display()))?;
    std::fs::rename(&tmp, path).map_err(|e| format!("{}: {e}", path.display()))
}

/// A deterministic zip (fixed timestamps, given order) written through a temporary file of
/// this process; the FMUs are stored (already compressed), the rest deflated.
fn write_zip(path: &Path, entries: &[(String, Vec<u8>)]) -> std::result::Result<(), String> {
    let tmp = path.with_extension(format!("ssp.{}.tmp", std::process::id()));
    let file = std::fs::File::create(&tmp).map_err(|e| format!("{}: {e}", tmp.display()))?;
    let mut zip = zip::ZipWriter::new(file);
    let options = SimpleFileOptions::default()
        .last_modified_time(zip::DateTime::default())
        .unix_permissions(0o644);
    for (name, bytes) in entries {
        let method = if name.ends_with(".fmu") {
            zip::CompressionMethod::Stored
        } else {
            zip::CompressionMethod::Deflated
        };
        zip.start_file(name.as_str(), options.compression_method(method))
            .map_err(|e| format!("{name}: {e}"))?;
        zip.write_all(bytes).map_err(|e| format!("{name}: {e}"))?;
    }
    zip.finish()
        .map_err(|e| format!("{}: {e}", tmp.display()))?;
    std::fs::rename(&tmp, path).map_err(|e| format!("{}: {e}", path.display()))
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    fn var(name: &str, causality: &str, type_name: &str, unit: Option<&str>) -> Variable {
        Variable {
            name: name.into(),
            causality: causality.into(),
            type_name: type_name.into(),
            unit: unit.map(Into::into),
        }
    }

    fn md(id: &str, variables: Vec<Variable>) -> ModelDescription {
        ModelDescription {
            model_name: id.into(),
            model_identifier: id.into(),
            step_size: Some("0.1".into()),
            units: ["m", "rad", "m/s", "N", "N.m"]
                .iter()
                .map(|u| (u.to_string(), vec![("name".into(), u.to_string())]))
                .collect(),
            variables,
        }
    }

    /// A plant and a controller shaped like the real ones: a vessel, a towline whose
    /// groups differ between the sides (a flag only the plant has), a tug's thrust.
    fn pair() -> (ModelDescription, ModelDescription) {
        let plant = md(
            "P",
            vec![
                var("scenario", "parameter", "String", None),
                var("tug1.force_surge", "input", "Real", Some("N")),
                var("tug1.moment_yaw", "input", "Real", Some("N.m")),
                var("ship.x", "output", "Real", Some("m")),
                var("ship.y", "output", "Real", Some("m")),
                var("ship.psi", "output", "Real", Some("rad")),
                var("ship.u", "output", "Real", Some("m/s")),
                var("towline1.tension", "output", "Real", Some("N")),
                var("towline1.slack", "output", "Boolean", None),
                var("towline1.mode", "output", "Integer", None),
                var("obstacle[1].kind", "output", "Integer", None),
            ],
        );
        let controller = md(
            "C",
            vec![
                var("ship.x", "input", "Real", Some("m")),
                var("ship.y", "input", "Real", Some("m")),
                var("ship.psi", "input", "Real", Some("rad")),
                var("ship.u", "input", "Real", Some("m/s")),
                var("towline1.tension", "input", "Real", Some("N")),
                var("towline1.mode", "input", "Integer", None),
                var("obstacle[1].kind", "input", "Enumeration", None),
                var("tug1.force_surge", "output", "Real", Some("N")),
                var("tug1.moment_yaw", "output", "Real", Some("N.m")),
                var("admm.iterations", "output", "Integer", None),
            ],
        );
        (plant, controller)
    }

    #[test]
    fn model_description_variables_types_and_declared_units() {
        let xml = r#"<fmiModelDescription fmiVersion="2.0" modelName="M" guid="g">
  <CoSimulation modelIdentifier="Mid"/>
  <UnitDefinitions><Unit name="m"><BaseUnit m="1"/></Unit></UnitDefinitions>
  <TypeDefinitions><SimpleType name="Length"><Real quantity="Length" unit="m"/></SimpleType></TypeDefinitions>
  <DefaultExperiment stepSize="0.1"/>
  <ModelVariables>
    <ScalarVariable name="a.x" valueReference="1" causality="output"><Real declaredType="Length"/></ScalarVariable>
    <ScalarVariable name="k" valueReference="2" causality="input"><Integer start="0"/></ScalarVariable>
  </ModelVariables>
</fmiModelDescription>"#;
        let md = parse_model_description(xml).unwrap();
        assert_eq!(md.model_name, "M");
        assert_eq!(md.model_identifier, "Mid");
        assert_eq!(md.step_size.as_deref(), Some("0.1"));
        assert_eq!(md.units, vec![("m".into(), vec![("m".into(), "1".into())])]);
        assert_eq!(
            md.variables,
            vec![
                var("a.x", "output", "Real", Some("m")),
                var("k", "input", "Integer", None)
            ]
        );
    }

    #[test]
    fn links_by_name_in_receiver_order_and_every_unfed_input_is_named() {
        let (plant, controller) = pair();
        let links = discover_links(&[&plant, &controller]).unwrap();
        let names: Vec<_> = links.iter().map(|l| (l.from, l.name.as_str())).collect();
        assert_eq!(
            names,
            vec![
                (0, "ship.x"),
                (0, "ship.y"),
                (0, "ship.psi"),
                (0, "ship.u"),
                (0, "towline1.tension"),
                (0, "towline1.mode"),
                (0, "obstacle[1].kind"),
                (1, "tug1.force_surge"),
                (1, "tug1.moment_yaw")
            ]
        );
        let mut broken = controller.clone();
        broken.variables.push(var("ship.r", "input", "Real", None));
        broken.variables[0].type_name = "Integer".into();
        let err = discover_links(&[&plant, &broken]).unwrap_err();
        assert!(
            err.contains("controller input 'ship.r' has no plant output"),
            "{err}"
        );
        assert!(
            err.contains("controller input 'ship.x' is Integer"),
            "{err}"
        );
    }

    #[test]
    fn groups_are_typed_runs_of_at_most_three_in_schema_order() {
        let (plant, _) = pair();
        let mut plant = plant;
        for m in ["a", "b", "c", "d"] {
            plant
                .variables
                .push(var(&format!("prediction.{m}"), "output", "Real", Some("m")));
        }
        let groups = variable_groups(&plant);
        let names: Vec<_> = groups.iter().map(|g| g.name.as_str()).collect();
        assert_eq!(
            names,
            vec![
                "tug1.in",
                "ship.out",
                "towline1.out",
                "obstacle[1].out",
                "prediction.out"
            ]
        );
        let ship = &groups[1];
        let subs: Vec<_> = ship
            .subgroups
            .iter()
            .map(|s| (s.osp_type, s.name.as_str()))
            .collect();
        assert_eq!(
            subs,
            vec![
                ("LinearVelocity", "ship.{u}"),
                ("LinearDisplacement", "ship.{x,y}"),
                ("AngularDisplacement", "ship.{psi}")
            ]
        );
        assert_eq!(groups[2].direct, vec!["towline1.slack", "towline1.mode"]);
        let prediction: Vec<_> = groups[4]
            .subgroups
            .iter()
            .map(|s| s.variables.len())
            .collect();
        assert_eq!(prediction, vec![3, 1]);
    }

    #[test]
    fn osp_connections_expand_to_exactly_the_links_by_name() {
        let (plant, controller) = pair();
        let mds = [&plant, &controller];
        let links = discover_links(&mds).unwrap();
        let connections = osp_connections(&mds, &links).unwrap();
        let g = |a: usize, x: &str, b: usize, y: &str| {
            OspConnection::Group((a, x.to_owned()), (b, y.to_owned()))
        };
        let v = |a: usize, b: usize, x: &str| {
            OspConnection::Variable((a, x.to_owned()), (b, x.to_owned()))
        };
        assert_eq!(
            connections,
            vec![
                g(0, "ship.out", 1, "ship.in"),
                // The plant's towline group has a flag the controller lacks: the typed
                // sub-groups connect, the rest variable by variable.
                g(0, "towline1.{tension}", 1, "towline1.{tension}"),
                // Integer and Enumeration are both connected as Integer.
                g(0, "obstacle[1].out", 1, "obstacle[1].in"),
                g(1, "tug1.out", 0, "tug1.in"),
                v(0, 1, "towline1.mode"),
            ]
        );
    }

    #[test]
    fn generated_files_name_every_connection_and_follow_the_schemas_order() {
        let (plant, controller) = pair();
        let models = [
            Model {
                instance: "plant".into(),
                path: "P.fmu".into(),
                description: plant,
            },
            Model {
                instance: "controller".into(),
                path: "C.fmu".into(),
                description: controller,
            },
        ];
        let generated = generate(&models).unwrap();
        let ssd = &generated.ssd;
        assert_eq!(ssd.matches("<ssd:Connection ").count(), 9);
        assert!(ssd.contains(
            "<ssd:Connection startElement=\"plant\" startConnector=\"ship.x\" endElement=\"controller\" endConnector=\"ship.x\"/>"
        ));
        assert!(ssd.contains("<ssd:Connector name=\"obstacle[1].kind\" kind=\"input\"><ssc:Integer/></ssd:Connector>"));
        assert!(ssd.contains("baseStepSize=\"0.1\""));
        let names: Vec<_> = generated
            .committed
            .iter()
            .map(|(n, _)| n.as_str())
            .collect();
        assert_eq!(
            names,
            vec![
                "OspSystemStructure.xml",
                "P_OspModelDescription.xml",
                "C_OspModelDescription.xml"
            ]
        );
        let structure = &generated.committed[0].1;
        let last_variable = structure.rfind("<VariableConnection>").unwrap();
        let first_group = structure.find("<VariableGroupConnection>").unwrap();
        assert!(last_variable < first_group);
        assert!(structure.contains("source=\"fmu/P.fmu\" stepSize=\"0.1\""));
        assert!(ssd.contains("<ssc:Unit name=\"N.m\"><ssc:BaseUnit name=\"N.m\"/></ssc:Unit>"));
        let mut clash = models.clone();
        clash[1].description.units[0].1 = vec![("m".into(), "2".into())];
        assert!(generate(&clash)
            .unwrap_err()
            .contains("define unit \"m\" differently"));
        // A different step in one FMU is refused.
        let mut other = models.clone();
        other[1].description.step_size = Some("0.05".into());
        assert!(generate(&other).unwrap_err().contains("different steps"));
    }

    #[test]
    fn committed_files_that_differ_or_are_missing_are_stale() {
        let dir = std::env::temp_dir().join(format!("xtask-ssp-test-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("same.xml"), "a\n").unwrap();
        std::fs::write(dir.join("edited.xml"), "b\n").unwrap();
        let committed = [
            ("same.xml".to_owned(), "a\n".to_owned()),
            ("edited.xml".to_owned(), "c\n".to_owned()),
            ("missing.xml".to_owned(), "d\n".to_owned()),
        ];
        let stale = stale_files(&dir, &committed);
        std::fs::remove_dir_all(&dir).unwrap();
        assert_eq!(
            stale,
            vec![
                dir.join("edited.xml").display().to_string(),
                dir.join("missing.xml").display().to_string()
            ]
        );
    }
}
