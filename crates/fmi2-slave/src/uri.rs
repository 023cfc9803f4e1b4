//! `fmuResourceLocation` (FMI 2.0 section 2.1.5, `fmi2Instantiate`): a `file:` URI of the
//! unzipped `resources` folder, turned into a path.

use std::path::PathBuf;

/// Converts the `fmuResourceLocation` argument of `fmi2Instantiate` into a directory path.
///
/// Accepted (what fmpy, libcosim and fmusim pass): `file:///abs/path`, `file:/abs/path`,
/// `file://localhost/abs/path`, scheme in any case, percent-encoded bytes (`%20`, UTF-8
/// sequences such as `%C3%A6`), with or without trailing slash (removed). `None` (a NULL
/// pointer) and the empty string give `Ok(None)`. The directory is not required to exist
/// (fmpy passes the URI even when the FMU has no resources).
///
/// Rejected with a message: other schemes (`http:`), relative references (`file:rel`,
/// `resources/`), a non-local host (`file://server/share`), malformed `%` escapes, `%00`,
/// and on Windows decoded bytes that are not UTF-8. `?` and `#` are taken literally.
///
/// On Windows `file:///C:/dir` becomes `C:/dir`.
pub fn resource_dir_from_uri(uri: Option<&str>) -> Result<Option<PathBuf>, String> {
    let Some(uri) = uri else {
        return Ok(None);
    };
    if uri.is_empty() {
        return Ok(None);
    }
    let scheme_ok = uri.len() >= 5 && uri.as_bytes()[..5].eq_ignore_ascii_case(b"file:");
    if !scheme_ok {
        return Err(format!(
            "fmuResourceLocation '{uri}' is not a file: URI (only local files are supported)"
        ));
    }
    let rest = &uri[5..];
    let path = if let Some(after) = rest.strip_prefix("//") {
        // authority present: empty or "localhost"
        let (host, path) = match after.find('/') {
            Some(i) => (&after[..i], &after[i..]),
            None => (after, ""),
        };
        if !(host.is_empty() || host.eq_ignore_ascii_case("localhost")) {
            return Err(format!(
                "fmuResourceLocation '{uri}' names the remote host '{host}'; only local files are supported"
            ));
        }
        if path.is_empty() {
            return Err(format!("fmuResourceLocation '{uri}' has no path"));
        }
        path
    } else if rest.starts_with('/') {
        rest
    } else {
        return Err(format!(
            "fmuResourceLocation '{uri}' is a relative file: URI; an absolute path is required"
        ));
    };
    let mut bytes =
        percent_decode(path).map_err(|e| format!("fmuResourceLocation '{uri}': {e}"))?;
    while bytes.len() > 1 && bytes.last() == Some(&b'/') {
        bytes.pop();
    }
    bytes_to_path(bytes)
        .map(Some)
        .map_err(|e| format!("fmuResourceLocation '{uri}': {e}"))
}

fn percent_decode(s: &str) -> Result<Vec<u8>, String> {
    let b = s.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%' {
            let hex = |c: Option<&u8>| c.and_then(|c| char::from(*c).to_digit(16));
            match (hex(b.get(i + 1)), hex(b.get(i + 2))) {
                (Some(hi), Some(lo)) => {
                    // hi, lo < 16, so the value fits in a byte.
                    let byte = u8::try_from(hi * 16 + lo).unwrap_or(0);
                    if byte == 0 {
                        return Err("contains %00".to_string());
                    }
                    out.push(byte);
                    i += 3;
                }
                _ => return Err(format!("malformed percent escape at byte {}", i + 1)),
            }
        } else {
            out.push(b[i]);
            i += 1;
        }
    }
    Ok(out)
}

#[cfg(unix)]
fn bytes_to_path(bytes: Vec<u8>) -> Result<PathBuf, String> {
    use std::os::unix::ffi::OsStringExt;
    Ok(PathBuf::from(std::ffi::OsString::from_vec(bytes)))
}

#[cfg(not(unix))]
fn bytes_to_path(bytes: Vec<u8>) -> Result<PathBuf, String> {
    let s = String::from_utf8(bytes).map_err(|_| "path is not valid UTF-8".to_string())?;
    // "/C:/dir" -> "C:/dir"
    let b = s.as_bytes();
    let s = if b.len() >= 3 && b[0] == b'/' && b[1].is_ascii_alphabetic() && b[2] == b':' {
        s[1..].to_string()
    } else {
        s
    };
    Ok(PathBuf::from(s))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    fn ok(uri: &str) -> PathBuf {
        match resource_dir_from_uri(Some(uri)) {
            Ok(Some(p)) => p,
            other => panic!("{uri}: {other:?}"),
        }
    }

    fn err(uri: &str) -> String {
        match resource_dir_from_uri(Some(uri)) {
            Err(e) => e,
            other => panic!("{uri} should fail: {other:?}"),
        }
    }

    #[test]
    fn null_and_empty_mean_no_resources() {
        assert_eq!(resource_dir_from_uri(None), Ok(None));
        assert_eq!(resource_dir_from_uri(Some("")), Ok(None));
    }

    #[cfg(unix)]
    #[test]
    fn the_three_file_forms_give_the_same_path() {
        let want = Path::new("/tmp/fmu/resources");
        assert_eq!(ok("file:///tmp/fmu/resources"), want);
        assert_eq!(ok("file:/tmp/fmu/resources"), want);
        assert_eq!(ok("file://localhost/tmp/fmu/resources"), want);
        assert_eq!(ok("FILE://LocalHost/tmp/fmu/resources"), want);
    }

    #[cfg(unix)]
    #[test]
    fn trailing_slash_is_removed() {
        let p = ok("file:///tmp/fmu/resources/");
        assert_eq!(p.as_os_str(), "/tmp/fmu/resources");
        assert_eq!(
            ok("file:///tmp/fmu/resources//").as_os_str(),
            "/tmp/fmu/resources"
        );
        assert_eq!(ok("file:///").as_os_str(), "/");
    }

    #[cfg(unix)]
    #[test]
    fn percent_encoding_spaces_and_utf8() {
        assert_eq!(
            ok("file:///tmp/my%20fmu/resources").as_os_str(),
            "/tmp/my fmu/resources"
        );
        assert_eq!(
            ok("file:///tmp/%C3%A6%C3%B8%C3%A5/r%c3%a9s").as_os_str(),
            "/tmp/æøå/rés"
        );
        // unencoded UTF-8 passes through too
        assert_eq!(ok("file:///tmp/æøå").as_os_str(), "/tmp/æøå");
        // '?' and '#' are literal
        assert_eq!(ok("file:///tmp/a#b?c").as_os_str(), "/tmp/a#b?c");
    }

    #[test]
    fn other_schemes_and_relative_references_are_rejected() {
        assert!(err("http://example.com/resources").contains("not a file: URI"));
        assert!(err("resources/").contains("not a file: URI"));
        assert!(err("/tmp/resources").contains("not a file: URI"));
        assert!(err("file:resources").contains("relative"));
        assert!(err("file://server/share/resources").contains("remote host 'server'"));
        assert!(err("file://").contains("no path"));
    }

    #[test]
    fn malformed_escapes_are_rejected() {
        assert!(err("file:///tmp/a%2").contains("malformed percent escape"));
        assert!(err("file:///tmp/a%zz").contains("malformed percent escape"));
        assert!(err("file:///tmp/a%00b").contains("%00"));
    }
}
