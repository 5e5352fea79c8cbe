//! `camchain fmu MODEL`: the model as an FMU (FMI 3.0, Co-Simulation).
//!
//! 1. The model file (a built-in model's text, or a `.ron` file) is checked and its module
//!    generated, as the build generates the built-in models.
//! 2. A crate is written under the cache (`camchain_compile`): the generated `src/model.rs`,
//!    a `src/lib.rs` that calls `camchain_fmu::export!(model::boxed)`, the workspace's
//!    `Cargo.lock`, and dependencies on the copies of the runtime (with its engine) and the
//!    FMU crate. cargo builds it into a library, kept in the crate's directory, so that a
//!    second export of the same text runs no cargo.
//! 3. The library is loaded and asked for its `modelDescription.xml`
//!    (`camchain_fmu_model_description`): the XML comes from the very model the binary
//!    serves, with the same value references and instantiation token.
//! 4. Both are packed into the FMU (a zip: `modelDescription.xml`,
//!    `binaries/<platform>/<identifier>.so`), written through a temporary file renamed into
//!    place, as every file of the command line is.

mod zip;

use super::CliError;
use super::args::FmuArgs;
use super::interrupt::Interrupt;
use super::source::{builtin_file, builtin_names};
use camchain_codegen::EmitOptions;
use camchain_codegen::schema::{Files, read_text};
use camchain_compile as compile;
use std::ffi::{CStr, CString, c_char};
use std::path::{Path, PathBuf};

/// The platform directory of the binary (FMI 3.0 §2.5.1) on the machines this export
/// supports.
fn platform() -> Result<String, CliError> {
    if cfg!(target_os = "linux") {
        Ok(format!("{}-linux", std::env::consts::ARCH))
    } else {
        Err(CliError::Failed(format!(
            "camchain fmu builds FMUs on Linux only (this is {})",
            std::env::consts::OS
        )))
    }
}

/// A model's name as the FMU's `modelIdentifier` (the library's file name, a C identifier):
/// letters, digits and underscores, not starting with a digit.
pub fn identifier(name: &str) -> String {
    let mut id: String = name
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
        .collect();
    if id.is_empty() || id.starts_with(|c: char| c.is_ascii_digit()) {
        id.insert(0, '_');
    }
    id
}

/// The model's text, how messages name it, where its tables are, and their texts (for the
/// cache key).
struct Source {
    text: String,
    shown: PathBuf,
    files: Files<'static>,
    files_dir: Option<PathBuf>,
}

fn source(model: &str) -> Result<Source, CliError> {
    if model.ends_with(".ron") || model.contains('/') || model.contains(std::path::MAIN_SEPARATOR) {
        let path = Path::new(model);
        let text = read_text(path)
            .map_err(|e| CliError::Failed(format!("{}: cannot read: {e}", path.display())))?;
        let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
        return Ok(Source {
            text,
            shown: path.to_path_buf(),
            files: Files::BesideModel,
            files_dir: Some(if dir.as_os_str().is_empty() {
                PathBuf::from(".")
            } else {
                dir
            }),
        });
    }
    let Some(text) = camchain_models::source(model) else {
        return Err(CliError::Usage(format!(
            "unknown model `{model}`: built-in models are {} (or give a path to a .ron file)",
            builtin_names().join(", ")
        )));
    };
    Ok(Source {
        text: text.to_string(),
        shown: builtin_file(model),
        files: Files::Embedded(camchain_models::files(model)),
        files_dir: None,
    })
}

/// Runs the command.
pub fn run(args: &FmuArgs, interrupt: &Interrupt) -> Result<(), CliError> {
    let platform = platform()?;
    if let Some(library) = &args.library {
        return pack_library(args, library, &platform);
    }
    let Some(model_arg) = args.model.as_deref() else {
        return Err(CliError::Usage(
            "give a MODEL (a built-in name or a .ron file) or --library FILE".into(),
        ));
    };
    let source = source(model_arg)?;
    let model = camchain_codegen::check_source_in(&source.text, &source.shown, source.files)
        .map_err(|e| CliError::Failed(e.to_string()))?;
    let id = identifier(&model.name);
    if let Some(builtin) = camchain_models::by_name(model_arg).filter(|_| args.describe) {
        let xml = camchain_fmu::description::model_description(builtin, &id);
        print!("{xml}");
        return Ok(());
    }
    let (out, _lock) = destination(args, &id)?;
    let options = EmitOptions {
        runtime_path: "::camchain_runtime".into(),
        files_dir: source.files_dir.clone(),
        ..EmitOptions::default()
    };
    let shown = source.shown.display().to_string();
    let generated = camchain_codegen::emit::generate_with(&model, &shown, &options)
        .map_err(|e| CliError::Failed(format!("{shown}: {e}")))?;
    let mut parts: Vec<&[u8]> = vec![
        b"fmu",
        source.text.as_bytes(),
        env!("CARGO_PKG_VERSION").as_bytes(),
    ];
    for file in &model.files {
        parts.push(file.written.as_bytes());
        parts.push(file.text.as_bytes());
    }
    let key = format!("{:016x}", compile::fnv(&parts));
    let root = compile::cache_root(args.cache.clone()).map_err(failed)?;
    let crate_dir = root.join("fmus").join(&key);
    let library = crate_dir.join(format!("{id}.so"));
    let stored = crate_dir.join("model.ron");
    let cached =
        library.is_file() && std::fs::read(&stored).is_ok_and(|s| s == source.text.as_bytes());
    if !cached {
        build(
            args,
            (&shown, &key, &id),
            &crate_dir,
            &root,
            &generated.code,
            &source.text,
            interrupt,
        )?;
    }
    let xml = describe(&library, &id)?;
    if args.describe {
        print!("{xml}");
        return Ok(());
    }
    pack(&out, &xml, &library, (&id, &platform))?;
    if !args.quiet {
        let from = if cached {
            ", library from the cache"
        } else {
            ""
        };
        eprintln!(
            "camchain fmu: wrote {} ({} for {platform}{from})",
            out.display(),
            model.name
        );
    }
    Ok(())
}

/// The FMU's path (`--out`, else `<id>.fmu`), checked and locked before anything is built, so
/// that no build is wasted on a path that cannot be written (no lock with `--describe`, which
/// writes no file).
fn destination(
    args: &FmuArgs,
    id: &str,
) -> Result<(PathBuf, Option<super::output::Lock>), CliError> {
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from(format!("{id}.fmu")));
    let lock = if args.describe {
        None
    } else {
        super::output::claim(&out).map_err(CliError::Failed)?
    };
    Ok((out, lock))
}

/// Writes the FMU: the description and the library as `binaries/<platform>/<id>.so`.
fn pack(
    out: &Path,
    xml: &str,
    library: &Path,
    (id, platform): (&str, &str),
) -> Result<(), CliError> {
    let binary = std::fs::read(library)
        .map_err(|e| CliError::Failed(format!("{}: {e}", library.display())))?;
    let entries = [
        ("modelDescription.xml".to_string(), xml.as_bytes().to_vec()),
        (format!("binaries/{platform}/{id}.so"), binary),
    ];
    super::output::write_file(out, |w| zip::write(w, &entries)).map_err(CliError::Failed)
}

/// `--library FILE`: a library a user's crate built (a cdylib calling `camchain::fmu::export!`),
/// checked and packed.
fn pack_library(args: &FmuArgs, library: &Path, platform: &str) -> Result<(), CliError> {
    if !library.is_file() {
        return Err(CliError::Failed(format!(
            "{}: no such library (build your crate's cdylib first: cargo build --release --lib)",
            library.display()
        )));
    }
    let stem = library
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let id = identifier(stem.strip_prefix("lib").unwrap_or(&stem));
    let (out, _lock) = destination(args, &id)?;
    let xml = describe(library, &id)?;
    if args.describe {
        print!("{xml}");
        return Ok(());
    }
    pack(&out, &xml, library, (&id, platform))?;
    if !args.quiet {
        eprintln!(
            "camchain fmu: wrote {} ({id} from {}, for {platform})",
            out.display(),
            library.display()
        );
    }
    Ok(())
}

fn failed(e: compile::Failure) -> CliError {
    CliError::Failed(format!("camchain fmu: {e}"))
}

/// Writes the crate and builds it; the library is copied into the crate's directory.
fn build(
    args: &FmuArgs,
    (shown, key, id): (&str, &str, &str),
    crate_dir: &Path,
    root: &Path,
    code: &str,
    text: &str,
    interrupt: &Interrupt,
) -> Result<(), CliError> {
    let sources = compile::sources(root).map_err(failed)?;
    let name = format!("camchain_fmu_{key}");
    let comment = format!("the FMU of {shown}");
    let manifest = compile::manifest(&name, &comment, compile::Links::Fmu, &sources);
    let lib = format!(
        "//! The FMU of `{shown}`, written by `camchain fmu`: the FMI 3.0 functions over the\n\
         //! generated model.\n\n\
         #[allow(clippy::all, unused, missing_docs)]\nmod model;\n\n\
         camchain_fmu::export!(model::boxed);\n"
    );
    compile::write_atomically(
        crate_dir,
        &[
            ("Cargo.toml".into(), manifest.into_bytes()),
            ("Cargo.lock".into(), compile::LOCKFILE.as_bytes().to_vec()),
            ("src/lib.rs".into(), lib.into_bytes()),
            ("src/model.rs".into(), code.as_bytes().to_vec()),
            ("model.ron".into(), text.as_bytes().to_vec()),
        ],
    )
    .map_err(failed)?;
    if !args.quiet {
        eprintln!(
            "camchain fmu: building {shown} with cargo (the first FMU of this version also \
             builds the runtime; later ones reuse it)"
        );
    }
    let mut stop = || interrupt.requested();
    let built =
        compile::build(crate_dir, &name, args.quiet, root, &mut stop).map_err(|e| match e {
            compile::Failure::Interrupted => interrupt.error(),
            e => failed(e),
        })?;
    let library = crate_dir.join(format!("{id}.so"));
    let temp = crate_dir.join(format!(".{id}.so.tmp-{}", std::process::id()));
    std::fs::copy(&built, &temp)
        .and_then(|_| std::fs::rename(&temp, &library))
        .map_err(|e| {
            let _ = std::fs::remove_file(&temp);
            CliError::Failed(format!("{} → {}: {e}", built.display(), library.display()))
        })
}

/// The library's own `modelDescription.xml`, once every FMI 3.0 function is found in it.
fn describe(library: &Path, id: &str) -> Result<String, CliError> {
    type Describe = unsafe extern "C" fn(*const c_char) -> *mut c_char;
    type Free = unsafe extern "C" fn(*mut c_char);
    let fail = |e: String| CliError::Failed(format!("{}: {e}", library.display()));
    // SAFETY: a library this command built from camchain-fmu's `export!`, whose two
    // functions have these signatures.
    unsafe {
        let lib = libloading::Library::new(library).map_err(|e| fail(e.to_string()))?;
        let missing: Vec<&str> = camchain_fmu::FMI3_FUNCTIONS
            .iter()
            .copied()
            .filter(|name| lib.get::<*const ()>(name.as_bytes()).is_err())
            .collect();
        if !missing.is_empty() {
            let more = missing.len().saturating_sub(4);
            let more = if more > 0 {
                format!(" and {more} more")
            } else {
                String::new()
            };
            return Err(fail(format!(
                "{} of the {} FMI 3.0 functions are missing ({}{more}): is it a library whose \
                 root calls camchain::fmu::export!?",
                missing.len(),
                camchain_fmu::FMI3_FUNCTIONS.len(),
                missing[..missing.len().min(4)].join(", ")
            )));
        }
        let describe: libloading::Symbol<Describe> =
            lib.get(b"camchain_fmu_model_description\0")
                .map_err(|e| fail(format!("{e}: not a library of camchain::fmu::export!")))?;
        let free: libloading::Symbol<Free> = lib
            .get(b"camchain_fmu_free_text\0")
            .map_err(|e| fail(e.to_string()))?;
        let id = CString::new(id).map_err(|e| fail(e.to_string()))?;
        let text = describe(id.as_ptr());
        if text.is_null() {
            return Err(fail("the library could not build its model".into()));
        }
        let xml = CStr::from_ptr(text).to_string_lossy().into_owned();
        free(text);
        Ok(xml)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn identifiers_are_c_identifiers() {
        assert_eq!(identifier("cycloidal_roller"), "cycloidal_roller");
        assert_eq!(identifier("my cam-2"), "my_cam_2");
        assert_eq!(identifier("4bar"), "_4bar");
        assert_eq!(identifier(""), "_");
    }
}
