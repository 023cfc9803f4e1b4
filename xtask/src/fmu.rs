//! Packaging of the FMUs: release build, model description check, zip.
//!
//! The modelDescription.xml of each FMU is generated from the Rust variable table by the FMU
//! crate's model description binary, committed under `modelDescription/`, and packaged from
//! there; packaging refuses to run when the committed file differs from the generated one.

use crate::{
    build_release, fail, output, progress, root, target_dir, Build, FmuCrate, Result, FMUS,
};
use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;
use zip::write::SimpleFileOptions;

/// Generated documents of one FMU, as printed by its model description binary.
struct Generated {
    xml: String,
    html: String,
    markdown: String,
    parameters: String,
}

/// Runs the FMU crate's model description binary of the last [`build_release`].
fn generate(fmu: &FmuCrate) -> Result<Generated> {
    let step = format!("generate model description of {}", fmu.model_identifier);
    let bin = target_dir().join("release").join(fmu.description_bin);
    let run_example = |what: &str| output(&step, Command::new(&bin).arg(what));
    Ok(Generated {
        xml: run_example("xml")?,
        html: run_example("html")?,
        markdown: run_example("markdown")?,
        parameters: run_example("parameters")?,
    })
}

fn committed_path(fmu: &FmuCrate) -> PathBuf {
    root()
        .join("modelDescription")
        .join(format!("{}.xml", fmu.model_identifier))
}

/// `cargo xtask model-description`: rewrites the committed model descriptions and the
/// generated variable tables of `docs/interface.md`.
pub fn write_model_descriptions() -> Result<()> {
    const STEP: &str = "write model description";
    let doc_path = root().join("docs/interface.md");
    let mut doc = std::fs::read_to_string(&doc_path)
        .or_else(|e| fail(STEP, format!("{}: {e}", doc_path.display())))?;
    build_release(Build::Products)?;
    for fmu in FMUS {
        let generated = generate(fmu)?;
        let path = committed_path(fmu);
        std::fs::write(&path, &generated.xml)
            .or_else(|e| fail(STEP, format!("{}: {e}", path.display())))?;
        progress(&format!("wrote {}", path.display()));
        doc = splice(&doc, fmu.model_identifier, "variables", &generated.markdown)
            .and_then(|d| {
                splice(
                    &d,
                    fmu.model_identifier,
                    "parameters",
                    &generated.parameters,
                )
            })
            .or_else(|e| fail(STEP, format!("{}: {e}", doc_path.display())))?;
    }
    std::fs::write(&doc_path, doc)
        .or_else(|e| fail(STEP, format!("{}: {e}", doc_path.display())))?;
    progress(&format!("wrote {}", doc_path.display()));
    Ok(())
}

/// Replaces the text between `<!-- BEGIN GENERATED: <id> <what> -->` and the matching END
/// marker with `table`.
fn splice(doc: &str, id: &str, what: &str, table: &str) -> std::result::Result<String, String> {
    let begin = format!("<!-- BEGIN GENERATED: {id} {what} -->\n");
    let end = format!("<!-- END GENERATED: {id} {what} -->");
    let a = doc
        .find(&begin)
        .ok_or_else(|| format!("marker {begin:?} not found"))?
        + begin.len();
    let b = doc[a..]
        .find(&end)
        .ok_or_else(|| format!("marker {end:?} not found"))?
        + a;
    Ok(format!("{}{table}{}", &doc[..a], &doc[b..]))
}

/// `cargo xtask fmu`: builds and packages every FMU; returns the paths of the .fmu files.
pub fn package_all() -> Result<Vec<PathBuf>> {
    let mut packages = Vec::new();
    build_release(Build::Products)?;
    for fmu in FMUS {
        packages.push(package(fmu)?);
    }
    Ok(packages)
}

fn package(fmu: &FmuCrate) -> Result<PathBuf> {
    let step = format!("package {}.fmu", fmu.model_identifier);
    let generated = generate(fmu)?;
    let committed_path = committed_path(fmu);
    let committed = std::fs::read_to_string(&committed_path).unwrap_or_default();
    if committed != generated.xml {
        return fail(
            &step,
            format!(
                "{} differs from the model description generated from the Rust variable table; \
                 run `cargo xtask model-description` and commit the result",
                committed_path.display()
            ),
        );
    }
    let library = target_dir()
        .join("release")
        .join(format!("lib{}.so", fmu.lib_name));
    let binary = std::fs::read(&library)
        .or_else(|e| fail(&step, format!("cannot read {}: {e}", library.display())))?;

    let mut entries: Vec<(String, Vec<u8>)> = vec![
        ("modelDescription.xml".into(), generated.xml.into_bytes()),
        (
            format!("binaries/linux64/{}.so", fmu.model_identifier),
            binary,
        ),
        (
            "documentation/index.html".into(),
            generated.html.into_bytes(),
        ),
    ];
    for (source, name) in fmu.resources {
        let path = root().join(source);
        let bytes = std::fs::read(&path)
            .or_else(|e| fail(&step, format!("cannot read {}: {e}", path.display())))?;
        entries.push((format!("resources/{name}"), bytes));
    }

    let out_dir = target_dir().join("fmu");
    std::fs::create_dir_all(&out_dir)
        .or_else(|e| fail(&step, format!("cannot create {}: {e}", out_dir.display())))?;
    let fmu_path = out_dir.join(format!("{}.fmu", fmu.model_identifier));
    write_zip(&fmu_path, &entries).or_else(|e| fail(&step, e))?;
    progress(&format!("wrote {}", fmu_path.display()));
    Ok(fmu_path)
}

/// Writes a deterministic zip (fixed timestamps, fixed order) via a temporary file of this
/// process, so a master never sees a half-written FMU and two packagings at once (two test
/// runs) do not take each other's file away.
fn write_zip(path: &Path, entries: &[(String, Vec<u8>)]) -> std::result::Result<(), String> {
    let tmp = path.with_extension(format!("fmu.{}.tmp", std::process::id()));
    let file = std::fs::File::create(&tmp).map_err(|e| format!("{}: {e}", tmp.display()))?;
    let mut zip = zip::ZipWriter::new(file);
    let options = SimpleFileOptions::default()
        .compression_method(zip::CompressionMethod::Deflated)
        .last_modified_time(zip::DateTime::default());
    for (name, bytes) in entries {
        let options = if name.starts_with("binaries/") {
            options.unix_permissions(0o755)
        } else {
            options.unix_permissions(0o644)
        };
        zip.start_file(name.as_str(), options)
            .map_err(|e| format!("{name}: {e}"))?;
        zip.write_all(bytes).map_err(|e| format!("{name}: {e}"))?;
    }
    zip.finish()
        .map_err(|e| format!("{}: {e}", tmp.display()))?;
    std::fs::rename(&tmp, path)
        .map_err(|e| format!("renaming {} to {}: {e}", tmp.display(), path.display()))
}
