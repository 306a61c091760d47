//! `--subroutine-path`: the folders where `o<name> call` finds `name.ngc`, as LinuxCNC's
//! SUBROUTINE_PATH.
//!
//! Owns the search (folders in the order given, the name lower-cased first, then as
//! written; a name with a path separator or a leading dot is found nowhere) and the
//! reading of a subroutine file; it must not interpret G-code (the
//! front end reads the file's text through [`pvt_gcode::SubroutineFiles`]).

use std::path::PathBuf;

/// The folders searched, in order.
#[derive(Debug, Clone)]
pub struct SubroutinePath(pub Vec<PathBuf>);

impl SubroutinePath {
    /// The folders of `--subroutine-path` values, each a folder or a `:`-separated list.
    pub fn from_args(values: &[String]) -> SubroutinePath {
        SubroutinePath(
            values
                .iter()
                .flat_map(|v| v.split(':'))
                .filter(|d| !d.is_empty())
                .map(PathBuf::from)
                .collect(),
        )
    }
}

impl pvt_gcode::SubroutineFiles for SubroutinePath {
    fn read(&self, name: &str) -> Result<Option<pvt_gcode::SubroutineFile>, String> {
        // A name is a file name in one of the folders, never a path out of them.
        if name.contains(['/', '\\']) || name.trim_start().starts_with('.') {
            return Ok(None);
        }
        let lower: String = name
            .chars()
            .filter(|c| !c.is_whitespace())
            .map(|c| c.to_ascii_lowercase())
            .collect();
        for dir in &self.0 {
            for file in [format!("{lower}.ngc"), format!("{}.ngc", name.trim())] {
                let path = dir.join(&file);
                if !path.is_file() {
                    continue;
                }
                return match std::fs::read(&path) {
                    Ok(bytes) => Ok(Some(pvt_gcode::SubroutineFile {
                        name: path.display().to_string(),
                        text: String::from_utf8_lossy(&bytes).into_owned(),
                    })),
                    Err(e) => Err(format!("cannot read {}: {e}", path.display())),
                };
            }
        }
        Ok(None)
    }

    fn describe(&self) -> String {
        let dirs: Vec<String> = self.0.iter().map(|d| d.display().to_string()).collect();
        format!("--subroutine-path {}", dirs.join(":"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use pvt_gcode::SubroutineFiles;

    #[test]
    fn folders_are_searched_in_order_lower_case_first() {
        let first = tempfile::tempdir().unwrap();
        let second = tempfile::tempdir().unwrap();
        std::fs::write(second.path().join("bore.ngc"), "second").unwrap();
        let path = SubroutinePath::from_args(&[format!(
            "{}:{}",
            first.path().display(),
            second.path().display()
        )]);
        assert_eq!(path.0.len(), 2);
        assert_eq!(path.read("BORE").unwrap().unwrap().text, "second");
        std::fs::write(first.path().join("bore.ngc"), "first").unwrap();
        assert_eq!(path.read("bore").unwrap().unwrap().text, "first");
        assert_eq!(path.read("other").unwrap(), None);
        std::fs::write(first.path().join("up.ngc"), "outside").unwrap();
        let inner = first.path().join("inner");
        std::fs::create_dir(&inner).unwrap();
        let path = SubroutinePath(vec![inner]);
        assert_eq!(path.read("../up").unwrap(), None);
        assert_eq!(path.read("..").unwrap(), None);
    }
}
