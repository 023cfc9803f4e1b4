//! The project's Python environment (`.venv`): fmpy and libcosimpy from the package registry.
//!
//! Installed from `masters/requirements.txt` (pinned versions). A stamp file holding the
//! requirements text makes a second run a no-op; a changed requirements file reinstalls.

use crate::{fail, progress, root, run, Result};
use std::path::PathBuf;
use std::process::Command;

/// Runs `work` while [`ensure_env`] sets the venv up in a thread (pip waits on the network,
/// cargo on the CPU: on a fresh machine this hides the half minute pip takes); returns the
/// venv's python and `work`'s result. When both fail, `work`'s error is the one reported.
pub fn ensure_env_during<T>(work: impl FnOnce() -> Result<T>) -> Result<(PathBuf, T)> {
    let venv = std::thread::spawn(ensure_env);
    let done = work();
    let python = venv.join().unwrap_or_else(|_| {
        fail(
            "set up the Python environment",
            "the set-up thread panicked",
        )
    });
    let done = done?;
    Ok((python?, done))
}

/// Ensures `.venv` exists with the pinned requirements; returns the venv's python.
pub fn ensure_env() -> Result<PathBuf> {
    const STEP: &str = "python environment";
    let root = root();
    let venv = root.join(".venv");
    let python = venv.join("bin/python");
    let requirements_path = root.join("masters/requirements.txt");
    let requirements = std::fs::read_to_string(&requirements_path).or_else(|e| {
        fail(
            STEP,
            format!("cannot read {}: {e}", requirements_path.display()),
        )
    })?;
    let stamp = venv.join(".requirements-installed");
    if python.exists() && std::fs::read_to_string(&stamp).ok().as_deref() == Some(&requirements) {
        return Ok(python);
    }

    if !python.exists() {
        let host = host_python()?;
        if run(STEP, Command::new(&host).args(["-m", "venv"]).arg(&venv)).is_err() {
            // Debian's python3 needs python3-venv for `-m venv`.
            install_venv_support()?;
            let _ = std::fs::remove_dir_all(&venv);
            run(STEP, Command::new(&host).args(["-m", "venv"]).arg(&venv))?;
        }
    }
    run(
        STEP,
        Command::new(&python).args(["-m", "pip", "install", "--quiet", "--upgrade", "pip"]),
    )?;
    run(
        STEP,
        Command::new(&python)
            .args(["-m", "pip", "install", "--quiet", "-r"])
            .arg(&requirements_path),
    )?;
    std::fs::write(&stamp, &requirements)
        .or_else(|e| fail(STEP, format!("cannot write {}: {e}", stamp.display())))?;
    progress(&format!("python environment ready: {}", python.display()));
    Ok(python)
}

fn host_python() -> Result<String> {
    for candidate in ["python3", "python"] {
        if Command::new(candidate)
            .arg("--version")
            .output()
            .is_ok_and(|o| o.status.success())
        {
            return Ok(candidate.to_owned());
        }
    }
    install_venv_support()?;
    Ok("python3".to_owned())
}

fn install_venv_support() -> Result<()> {
    const STEP: &str = "install python3-venv with apt-get";
    progress("python3 -m venv is not available; installing Debian's python3-venv");
    run(STEP, Command::new("apt-get").arg("update"))?;
    run(
        STEP,
        Command::new("apt-get").args(["install", "-y", "python3", "python3-venv", "python3-pip"]),
    )
}
