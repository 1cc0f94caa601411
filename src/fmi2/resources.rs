//! What an FMU is built from ([`Source`]), how it is stored in the FMU's `resources/` folder, and
//! how the folder is found from the `fmuResourceLocation` URI importers pass to `fmi2Instantiate`.
//!
//! | file in `resources/` | written for | content |
//! |---|---|---|
//! | `parallel_arch.json` | the default FMU (`ParallelArch`) | the [`ParallelArch`] parameters (serde) |
//! | `model.json` | `fmu-pack model.json` | the validated model, as `Model::to_json` writes it |
//!
//! URI forms accepted (FMI 2.0 §2.1.5 and what importers really send):
//! `file:///abs/path` (percent-encoded: fmpy, FMIL, libcosim), `file:/abs/path`,
//! `file://localhost/abs/path`, OMSimulator's `file:////abs/path` with no encoding at all, a
//! trailing slash, a case-insensitive scheme. Percent-decoding acts only on valid `%XX`; when the
//! decoded path does not exist but the raw one does (an unencoded path holding `%`), the raw one
//! is used. On Windows the path of `file:///C:/dir/resources` is `C:/dir/resources` (RFC 8089,
//! appendix E.2: a drive letter after the leading slash).

use std::path::{Path, PathBuf};

use crate::mech::Model;
use crate::specimens::ParallelArch;

/// File name of a ParallelArch specification in `resources/`.
pub const SPECIMEN_FILE: &str = "parallel_arch.json";
/// File name of a user model in `resources/`.
pub const MODEL_FILE: &str = "model.json";

/// What an FMU is built from.
#[derive(Clone, Debug, PartialEq)]
#[allow(clippy::large_enum_variant)] // one per instance; the specimen holds a material's inline hardening table
pub enum Source {
    /// The paper's specimen generator; the model is regenerated at initialization from
    /// `archHeight` (and these parameters).
    ParallelArch(ParallelArch),
    /// A user model.
    Model(Model),
}

impl Source {
    /// The model at the start values (for the specimen: generated now).
    pub fn model(&self) -> Result<Model, String> {
        match self {
            Self::ParallelArch(spec) => spec.model(),
            Self::Model(m) => Ok(m.clone()),
        }
    }

    /// The resource file: its name and content.
    pub fn resource_file(&self) -> (&'static str, String) {
        match self {
            Self::ParallelArch(spec) => (
                SPECIMEN_FILE,
                serde_json::to_string_pretty(spec).expect("a specimen always serializes"),
            ),
            Self::Model(m) => (MODEL_FILE, m.to_json()),
        }
    }

    /// Reads the source back from a resource file's name and content.
    pub fn from_resource(name: &str, text: &str) -> Result<Self, String> {
        match name {
            SPECIMEN_FILE => {
                let spec: ParallelArch = serde_json::from_str(text)
                    .map_err(|e| format!("resources/{SPECIMEN_FILE}: {e}"))?;
                spec.check()
                    .map_err(|e| format!("resources/{SPECIMEN_FILE}: {e}"))?;
                Ok(Self::ParallelArch(spec))
            }
            MODEL_FILE => Model::from_json(text)
                .map(Self::Model)
                .map_err(|e| format!("resources/{MODEL_FILE}: {e}")),
            other => Err(format!("unknown resource file '{other}'")),
        }
    }

    /// Loads the source from an unpacked `resources/` directory.
    pub fn load(dir: &Path) -> Result<Self, String> {
        for name in [SPECIMEN_FILE, MODEL_FILE] {
            let path = dir.join(name);
            if path.is_file() {
                let text = std::fs::read_to_string(&path)
                    .map_err(|e| format!("{}: {e}", path.display()))?;
                return Self::from_resource(name, &text);
            }
        }
        Err(format!(
            "{} holds neither {SPECIMEN_FILE} nor {MODEL_FILE}",
            dir.display()
        ))
    }

    /// Writes the resource file into `dir` (which must exist).
    pub fn save(&self, dir: &Path) -> std::io::Result<PathBuf> {
        let (name, text) = self.resource_file();
        let path = dir.join(name);
        std::fs::write(&path, text)?;
        Ok(path)
    }
}

/// The `file:///…` URI of a local absolute path, percent-encoded as fmpy sends it (RFC 3986:
/// everything but unreserved characters and `/`). For in-process hosts such as benchmarks.
/// A Windows path `C:\dir` becomes `file:///C:/dir`.
pub fn file_uri(path: &Path) -> String {
    let mut uri = String::from("file://");
    let bytes = path.as_os_str().as_encoded_bytes();
    let windows = cfg!(windows);
    if windows && bytes.get(1) == Some(&b':') {
        uri.push('/');
    }
    for (i, &b) in bytes.iter().enumerate() {
        if windows && b == b'\\' {
            uri.push('/');
        } else if windows && i == 1 && b == b':' {
            uri.push(':');
        } else if b.is_ascii_alphanumeric() || b"-._~/".contains(&b) {
            uri.push(b as char);
        } else {
            uri.push_str(&format!("%{b:02X}"));
        }
    }
    uri
}

/// The local directory named by an `fmuResourceLocation` URI.
pub fn resource_dir(uri: &str) -> Result<PathBuf, String> {
    let (raw, decoded) = uri_paths(uri)?;
    if !decoded.exists() && raw.exists() {
        return Ok(raw);
    }
    Ok(decoded)
}

/// The path of a `file:` URI, decoded and raw (without existence checks).
fn uri_paths(uri: &str) -> Result<(PathBuf, PathBuf), String> {
    let bad = |why: &str| format!("fmuResourceLocation '{uri}': {why}");
    let colon = uri.find(':').ok_or_else(|| bad("not a URI (no scheme)"))?;
    let (scheme, rest) = (&uri[..colon], &uri[colon + 1..]);
    if !scheme.eq_ignore_ascii_case("file") {
        return Err(bad("only file: URIs are supported"));
    }
    // "//authority/path": the authority may be empty or localhost. More than two slashes
    // (OMSimulator's "file:////tmp") mean an empty authority and extra slashes in the path.
    let path = if let Some(after) = rest.strip_prefix("//") {
        if after.starts_with('/') {
            after
        } else {
            let end = after.find('/').unwrap_or(after.len());
            let authority = &after[..end];
            if !authority.eq_ignore_ascii_case("localhost") {
                return Err(bad(&format!("host '{authority}' is not local")));
            }
            &after[end..]
        }
    } else {
        rest
    };
    if !path.starts_with('/') {
        return Err(bad("the path is not absolute"));
    }
    let normalize = |p: &[u8]| -> PathBuf {
        let trimmed_start = p
            .iter()
            .position(|&b| b != b'/')
            .map_or(&p[p.len()..], |i| &p[i..]);
        let mut bytes = Vec::with_capacity(trimmed_start.len() + 1);
        bytes.push(b'/');
        bytes.extend_from_slice(trimmed_start);
        while bytes.len() > 1 && bytes.last() == Some(&b'/') {
            bytes.pop();
        }
        local_path(bytes)
    };
    Ok((
        normalize(path.as_bytes()),
        normalize(&percent_decode(path.as_bytes())),
    ))
}

/// The local path of a URI's decoded path bytes (`/abs/path`). Unix takes the bytes as they are;
/// Windows reads them as UTF-8 and drops the slash before a drive letter (`/C:/x` → `C:/x`).
#[cfg(unix)]
fn local_path(bytes: Vec<u8>) -> PathBuf {
    use std::os::unix::ffi::OsStringExt;
    PathBuf::from(std::ffi::OsString::from_vec(bytes))
}

#[cfg(not(unix))]
fn local_path(bytes: Vec<u8>) -> PathBuf {
    PathBuf::from(without_slash_before_drive(&String::from_utf8_lossy(&bytes)))
}

/// `/C:/dir` → `C:/dir` (a URI path's drive letter, RFC 8089 appendix E.2); anything else as is.
#[cfg_attr(unix, allow(dead_code))] // used on Windows, tested everywhere
fn without_slash_before_drive(path: &str) -> &str {
    match path.as_bytes() {
        [b'/', drive, b':', ..] if drive.is_ascii_alphabetic() => &path[1..],
        _ => path,
    }
}

/// Decodes valid `%XX` sequences; anything else is kept as it is.
fn percent_decode(s: &[u8]) -> Vec<u8> {
    let hex = |b: u8| (b as char).to_digit(16).map(|d| d as u8);
    let mut out = Vec::with_capacity(s.len());
    let mut i = 0;
    while i < s.len() {
        if s[i] == b'%'
            && i + 2 < s.len()
            && let (Some(h), Some(l)) = (hex(s[i + 1]), hex(s[i + 2]))
        {
            out.push(h << 4 | l);
            i += 3;
            continue;
        }
        out.push(s[i]);
        i += 1;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn decoded(uri: &str) -> String {
        uri_paths(uri).unwrap().1.to_string_lossy().into_owned()
    }

    #[test]
    fn windows_drive_letters() {
        assert_eq!(
            without_slash_before_drive("/C:/dir/resources"),
            "C:/dir/resources"
        );
        assert_eq!(without_slash_before_drive("/z:"), "z:");
        assert_eq!(without_slash_before_drive("/tmp/C:/x"), "/tmp/C:/x");
        assert_eq!(without_slash_before_drive("/1:/x"), "/1:/x");
    }

    #[test]
    fn uri_forms_importers_send() {
        // fmpy / FMIL / libcosim: three slashes, percent-encoded.
        assert_eq!(
            decoded("file:///tmp/tmpab12/resources"),
            "/tmp/tmpab12/resources"
        );
        assert_eq!(
            decoded("file:///tmp/tmp%20dir%20%C3%A9/resources"),
            "/tmp/tmp dir é/resources"
        );
        assert_eq!(
            decoded("file:///tmp/a%23b%25c/resources"),
            "/tmp/a#b%c/resources"
        );
        // No authority, localhost, upper-case scheme, trailing slash.
        assert_eq!(decoded("file:/tmp/x/resources"), "/tmp/x/resources");
        assert_eq!(
            decoded("file://localhost/tmp/x/resources"),
            "/tmp/x/resources"
        );
        assert_eq!(decoded("FILE:///tmp/x/resources/"), "/tmp/x/resources");
        // OMSimulator: four slashes, nothing encoded.
        assert_eq!(
            decoded("file:////tmp/dir with space#ü/resources"),
            "/tmp/dir with space#ü/resources"
        );
        // Invalid escapes are kept.
        assert_eq!(decoded("file:///tmp/100%/x%zz%4"), "/tmp/100%/x%zz%4");
    }

    #[test]
    fn uri_errors() {
        for (uri, why) in [
            ("/tmp/x", "no scheme"),
            ("http://host/x", "only file:"),
            ("file://server/share/x", "not local"),
            ("file:relative/x", "not absolute"),
        ] {
            let err = uri_paths(uri).unwrap_err();
            assert!(err.contains(why), "{uri}: {err}");
        }
    }

    #[test]
    fn file_uri_round_trips() {
        let path = Path::new("/tmp/a b/é%#/resources");
        let uri = file_uri(path);
        assert_eq!(uri, "file:///tmp/a%20b/%C3%A9%25%23/resources");
        assert_eq!(uri_paths(&uri).unwrap().1, path);
    }

    #[test]
    fn raw_path_wins_when_only_it_exists() {
        // An unencoded path with "%41" in it (OMSimulator): decoding would give "A".
        let dir = std::env::temp_dir().join(format!("mc-uri-%41-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let uri = format!("file:///{}", dir.display());
        assert_eq!(resource_dir(&uri).unwrap(), dir);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn sources_round_trip_through_their_resource_file() {
        let spec = Source::ParallelArch(ParallelArch::with_height(0.2));
        let (name, text) = spec.resource_file();
        assert_eq!(Source::from_resource(name, &text).unwrap(), spec);
        let model = Source::Model(ParallelArch::with_height(0.4).model().unwrap());
        let (name, text) = model.resource_file();
        assert_eq!(
            Source::from_resource(name, &text).unwrap(),
            model,
            "floats survive the JSON exactly"
        );
        let err = Source::from_resource(MODEL_FILE, "{}").unwrap_err();
        assert!(err.starts_with("resources/model.json: "), "{err}");
    }
}
