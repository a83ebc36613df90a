//! Every command the README shows, run as a user would type it: from a folder holding the
//! course's files by their names (and `docs/` of this repository, and `../shared`), each
//! line through `sh`, with this build's `prism` first on the PATH.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::SystemTime;

use super::{scratch, stderr};

/// The commands of the README with the exit code each should give: each line of its `sh`
/// code blocks that runs `prism` (alone, after `VAR=value`, in a `for` loop or after
/// `mkdir -p ... &&`), and each `prism ...` in the table of systems, without trailing
/// comments; 0 unless the line's comment states `exit N`.
fn readme_commands(readme: &str) -> Vec<(String, i32)> {
    let mut commands = Vec::new();
    let mut in_sh = false;
    for line in readme.lines() {
        let t = line.trim();
        if t.starts_with("```") {
            in_sh = !in_sh && t == "```sh";
            continue;
        }
        if in_sh {
            let (command, comment) = match t.find("  #") {
                Some(i) => (t[..i].trim_end(), &t[i..]),
                None => (t, ""),
            };
            let exit = comment
                .split("exit ")
                .nth(1)
                .and_then(|r| r.split(|c: char| !c.is_ascii_digit()).next())
                .and_then(|n| n.parse().ok())
                .unwrap_or(0);
            let words: Vec<&str> = command.split_whitespace().collect();
            let first_program = words.iter().find(|w| !w.contains('=')).copied();
            let runs_prism = command.contains("prism ")
                && matches!(first_program, Some("prism" | "for" | "mkdir"));
            if runs_prism {
                commands.push((command.to_string(), exit));
            }
        } else if t.starts_with('|') {
            for (i, span) in t.split('`').enumerate() {
                // A command with its arguments (the gallery's `prism cloth` names one only).
                let full = span.split_whitespace().count() >= 3;
                if i % 2 == 1 && span.starts_with("prism ") && full && span != "prism view FILE" {
                    commands.push((span.to_string(), 0));
                }
            }
        }
    }
    commands
}

/// Every regular file under `dir`, by path.
fn files_under(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let e = e.unwrap();
            let t = e.file_type().unwrap();
            if t.is_dir() {
                stack.push(e.path());
            } else if t.is_file() {
                out.push(e.path());
            }
        }
    }
    out.sort();
    out
}

/// The working folder the README's lines run in: a link per course file by its name (the
/// first in path order when two share one), a link per course folder, `docs`, and
/// `../shared` beside it.
fn stage(root: &Path) -> PathBuf {
    let assets = prism_testkit::shared_assets();
    let work = root.join("work");
    std::fs::create_dir_all(&work).unwrap();
    let link = |target: &Path, name: &Path| std::os::unix::fs::symlink(target, name).unwrap();
    let mut by_name = BTreeMap::new();
    for f in files_under(&assets) {
        by_name
            .entry(f.file_name().unwrap().to_owned())
            .or_insert(f);
    }
    for (name, path) in &by_name {
        link(path, &work.join(name));
    }
    for e in std::fs::read_dir(&assets).unwrap() {
        let e = e.unwrap();
        if e.file_type().unwrap().is_dir() {
            link(&e.path(), &work.join(e.file_name()));
        }
    }
    link(
        &prism_testkit::workspace_root().join("docs"),
        &work.join("docs"),
    );
    link(&assets.join(".."), &root.join("shared"));
    work
}

/// The files under `dir` (links not followed) with their modification times.
fn snapshot(dir: &Path) -> BTreeMap<PathBuf, SystemTime> {
    files_under(dir)
        .into_iter()
        .filter_map(|p| {
            let t = std::fs::symlink_metadata(&p)
                .and_then(|m| m.modified())
                .ok()?;
            Some((p, t))
        })
        .collect()
}

/// The README's commands all run: each exits 0, writes something, and every PNG it writes
/// is not blank (black or any one colour) (`mesh info` prints instead). `prism view` lines, which need a display, are
/// run without one: each opens its file in its mode and then exits 2 saying a display is
/// needed (`scripts/view-check.sh` drives the real window).
#[test]
fn every_readme_command_runs() {
    let root = scratch("readme");
    let work = stage(&root);
    let readme =
        std::fs::read_to_string(prism_testkit::workspace_root().join("README.md")).unwrap();
    let commands = readme_commands(&readme);
    assert!(
        commands.len() >= 50,
        "{} commands: {commands:#?}",
        commands.len()
    );
    let bin = Path::new(env!("CARGO_BIN_EXE_prism")).parent().unwrap();
    let path = format!(
        "{}:{}",
        bin.display(),
        std::env::var("PATH").unwrap_or_default()
    );
    for (command, exit) in &commands {
        let before = snapshot(&work);
        let o = Command::new("sh")
            .args(["-c", command])
            .current_dir(&work)
            .env("PATH", &path)
            .env_remove("DISPLAY")
            .env_remove("PRISM_DATA")
            .output()
            .unwrap();
        if command.starts_with("prism view") {
            assert_eq!(o.status.code(), Some(2), "{command}: {}", stderr(&o));
            assert!(
                stderr(&o).contains("needs an X11 display"),
                "{command}: {}",
                stderr(&o)
            );
            continue;
        }
        assert_eq!(o.status.code(), Some(*exit), "{command}: {}", stderr(&o));
        if *exit != 0 {
            continue;
        }
        if command.contains(" info ") {
            assert!(!o.stdout.is_empty(), "{command}: printed nothing");
            continue;
        }
        let written: Vec<PathBuf> = snapshot(&work)
            .into_iter()
            .filter(|(p, t)| before.get(p) != Some(t))
            .map(|(p, _)| p)
            .collect();
        assert!(!written.is_empty(), "{command}: wrote nothing");
        for file in written
            .iter()
            .filter(|p| p.extension().is_some_and(|e| e == "png"))
        {
            let img = prism_image::read_png(file)
                .unwrap_or_else(|e| panic!("{command}: {}: {e}", file.display()));
            // Not blank: a black (or any single-colour) picture is one pixel value repeated.
            let first = img.pixels()[0];
            let varied = img.pixels().iter().any(|p| *p != first);
            assert!(varied, "{command}: {} is one flat colour", file.display());
        }
    }
}
