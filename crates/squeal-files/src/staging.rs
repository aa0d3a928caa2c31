//! What squeal owns on disk, and how it replaces it.
//!
//! - Every output folder squeal writes holds a manifest, [`MANIFEST`],
//!   listing the files squeal wrote there. Only a folder that is empty or
//!   holds a valid manifest may be replaced, and only if everything in it is
//!   listed: a folder with anything else in it (a user's note, a `main.c`
//!   beside a `report.md`) is refused, naming that entry. Nothing the
//!   manifest does not list is ever deleted.
//! - A symbolic link given as the output is refused (squeal writes real
//!   folders and files only, never through a link).
//! - Output is written into a staging folder beside the destination, named
//!   `.squeal-<pid>-<hash>.new` (short whatever the destination's name),
//!   and swapped into place in one step (`renameat2(RENAME_EXCHANGE)` on
//!   Linux; elsewhere two renames). Staging entries of processes that no
//!   longer run are removed by the next run into the same parent folder.
//! - A staging folder is made by exclusive creation (`mkdir` fails if the
//!   name exists) and at once given a marker, [`STAGE_MARKER`], holding the
//!   process id that made it. A stale staging folder is recognised by its
//!   marker and that process being gone; a folder merely named like one
//!   (no marker, another process id in it, or a live process) is never
//!   deleted. A single file (`listen --out`) is staged inside such a folder.
//! - SIGINT and SIGTERM remove the staging entries of the running process,
//!   and the parent folders it created for them, and end it with 130 or 143.

use crate::RunError;
use serde_json::{json, Value};
use squeal_study::scenario::InputError;
use std::path::{Component, Path, PathBuf};
use std::sync::Mutex;

/// The manifest file squeal writes into every output folder.
pub const MANIFEST: &str = ".squeal-manifest.json";

/// Prefix of staging entries (`.squeal-<pid>-<hash>.new|.old`).
const STAGE_PREFIX: &str = ".squeal-";

/// The marker file inside a staging folder: `{"written_by": "squeal",
/// "pid": …}`, written by the process that created the folder.
pub const STAGE_MARKER: &str = ".squeal-staging.json";

/// A staging entry of this process and the parent folders created for it
/// (outermost first), removed by the signal handler.
struct Live {
    tmp: PathBuf,
    created: Vec<PathBuf>,
}

/// Staging entries of this process, removed by the signal handler.
static LIVE: Mutex<Vec<Live>> = Mutex::new(Vec::new());

fn live() -> std::sync::MutexGuard<'static, Vec<Live>> {
    LIVE.lock().unwrap_or_else(|e| e.into_inner())
}

/// Forget the live entry `tmp` (committed or removed).
fn forget(live: &mut Vec<Live>, tmp: &Path) {
    live.retain(|l| l.tmp != tmp);
}

/// Remove the folders in `created` (innermost first) that are empty.
/// Create `parent` (whose missing folders are `created`), removing them
/// again if that fails, and clear stale staging entries out of it.
fn make_parent(parent: &Path, created: &[PathBuf]) -> Result<(), RunError> {
    if let Err(e) = std::fs::create_dir_all(parent) {
        remove_created(created);
        let p = parent.display();
        return Err(RunError::Io(format!("cannot create {p}: {e}")));
    }
    clean_stale(parent);
    Ok(())
}

fn remove_created(created: &[PathBuf]) {
    for d in created.iter().rev() {
        let _ = std::fs::remove_dir(d);
    }
}

/// The process id in a staging folder's marker, if it has a valid one.
fn marker_pid(dir: &Path) -> Option<u32> {
    let text = squeal_study::input::read_regular_text(&dir.join(STAGE_MARKER), 4096).ok()?;
    let v: Value = serde_json::from_str(&text).ok()?;
    if v["written_by"] != "squeal" {
        return None;
    }
    v["pid"].as_u64().and_then(|p| u32::try_from(p).ok())
}

/// Create the staging folder `tmp` exclusively and mark it as this
/// process's; `created` are the parent folders made for it. A folder
/// already there is ours only if its marker names this process and it is
/// not live (left by an earlier step of this run): it is then replaced;
/// anything else by that name is refused, never deleted.
fn make_stage(tmp: &Path, created: Vec<PathBuf>) -> Result<(), RunError> {
    let cannot = |e: std::io::Error| {
        RunError::Io(format!(
            "cannot write into {}: {e}",
            parent_of(tmp).display()
        ))
    };
    let mut live = live();
    match std::fs::create_dir(tmp) {
        Ok(()) => {}
        Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {
            let ours = std::fs::symlink_metadata(tmp).is_ok_and(|m| m.is_dir())
                && marker_pid(tmp) == Some(std::process::id())
                && !live.iter().any(|l| l.tmp == tmp);
            if !ours {
                remove_created(&created);
                return Err(RunError::Io(format!(
                    "cannot stage output: {} exists and was not made by this run of squeal; move it away",
                    tmp.display()
                )));
            }
            remove_partial(tmp);
            std::fs::create_dir(tmp).map_err(cannot)?;
        }
        Err(e) => {
            remove_created(&created);
            return Err(cannot(e));
        }
    }
    live.push(Live {
        tmp: tmp.to_path_buf(),
        created,
    });
    let marker = json!({ "written_by": "squeal", "pid": std::process::id() });
    std::fs::write(tmp.join(STAGE_MARKER), format!("{marker}\n")).map_err(cannot)?;
    Ok(())
}

/// Handle SIGINT and SIGTERM: remove this process's staging entries, then
/// exit with 128 + the signal number (130, 143).
pub fn install_signal_handlers() {
    use signal_hook::consts::{SIGINT, SIGTERM};
    let Ok(mut signals) = signal_hook::iterator::Signals::new([SIGINT, SIGTERM]) else {
        return;
    };
    std::thread::spawn(move || {
        if let Some(sig) = signals.forever().next() {
            // Holding the lock keeps a commit from starting meanwhile.
            let live = live();
            for l in live.iter() {
                remove_partial(&l.tmp);
                remove_created(&l.created);
            }
            let name = if sig == SIGINT { "SIGINT" } else { "SIGTERM" };
            if live.is_empty() {
                note!("interrupted ({name})");
            } else {
                note!("interrupted ({name}): partial output removed");
            }
            std::process::exit(128 + sig);
        }
    });
}

/// Remove an uncommitted staging entry (folder or file), retrying while a
/// writer may still add files to it.
fn remove_partial(p: &Path) {
    for _ in 0..50 {
        match std::fs::symlink_metadata(p) {
            Err(_) => return,
            Ok(m) if m.is_dir() => {
                let _ = std::fs::remove_dir_all(p);
            }
            Ok(_) => {
                let _ = std::fs::remove_file(p);
            }
        }
    }
}

/// FNV-1a, 64 bits: a short stable tag of a destination name.
fn fnv(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, b| {
        (h ^ u64::from(*b)).wrapping_mul(0x0100_0000_01b3)
    })
}

/// The staging name of `dest` for this process: `.squeal-<pid>-<hash>.<suffix>`.
fn stage_path(dest: &Path, suffix: &str) -> PathBuf {
    let name = dest
        .file_name()
        .map(|n| n.as_encoded_bytes())
        .unwrap_or(b"");
    parent_of(dest).join(format!(
        "{STAGE_PREFIX}{}-{:016x}.{suffix}",
        std::process::id(),
        fnv(name)
    ))
}

/// The PID in a staging entry's name, if it is one.
fn stage_pid(name: &str) -> Option<u32> {
    let rest = name.strip_prefix(STAGE_PREFIX)?;
    let (pid, rest) = rest.split_once('-')?;
    let (hash, suffix) = rest.split_once('.')?;
    (hash.len() == 16 && matches!(suffix, "new" | "old"))
        .then(|| pid.parse().ok())
        .flatten()
}

/// Whether a process with this PID exists.
fn alive(pid: u32) -> bool {
    let Some(p) = i32::try_from(pid)
        .ok()
        .and_then(rustix::process::Pid::from_raw)
    else {
        return false;
    };
    match rustix::process::test_kill_process(p) {
        Ok(()) => true,
        Err(e) => e != rustix::io::Errno::SRCH,
    }
}

fn parent_of(dest: &Path) -> &Path {
    dest.parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."))
}

/// Remove the staging entries of dead processes in `dir` (best effort).
pub fn clean_stale(dir: &Path) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries.flatten() {
        let name = e.file_name();
        let Some(pid) = name.to_str().and_then(stage_pid) else {
            continue;
        };
        // Only folders: squeal stages everything in a marked folder, so a
        // file by such a name is not squeal's.
        if pid != std::process::id() && !alive(pid) && e.file_type().is_ok_and(|t| t.is_dir()) {
            remove_owned(&e.path());
        }
    }
}

/// Remove a staging entry or a swapped-out output folder: wholesale if it
/// has no manifest (a staging folder not yet committed: squeal's alone);
/// otherwise only the manifest's files, the manifest and folders left empty.
/// Whatever else is in it stays (and is reported).
fn remove_owned(p: &Path) {
    let Ok(meta) = std::fs::symlink_metadata(p) else {
        return;
    };
    if !meta.is_dir() {
        let _ = std::fs::remove_file(p);
        return;
    }
    let files = match read_manifest(p) {
        Ok(Some(files)) => files,
        Ok(None) => {
            // No manifest: a staging folder not yet committed, removed
            // whole only if its marker says squeal made it under the pid in
            // its name; an empty folder goes too; anything else stays.
            let name_pid = p.file_name().and_then(|n| n.to_str()).and_then(stage_pid);
            if name_pid.is_some() && marker_pid(p) == name_pid {
                remove_partial(p);
            } else if std::fs::remove_dir(p).is_err() && p.exists() {
                note!(
                    "note: {} is named like a staging folder of squeal's but has no marker of it; left in place",
                    p.display()
                );
            }
            return;
        }
        Err(e) => {
            note!("note: {} left in place: {e}", p.display());
            return;
        }
    };
    for f in files.iter().filter(|f| no_link_on_the_way(p, f)) {
        let _ = std::fs::remove_file(p.join(f));
    }
    let _ = std::fs::remove_file(p.join(MANIFEST));
    let mut dirs: Vec<PathBuf> = walk(p)
        .unwrap_or_default()
        .into_iter()
        .filter(|e| e.is_dir)
        .map(|e| p.join(e.rel))
        .collect();
    dirs.sort_by_key(|d| std::cmp::Reverse(d.components().count()));
    for d in dirs {
        let _ = std::fs::remove_dir(d);
    }
    if std::fs::remove_dir(p).is_err() && p.exists() {
        note!(
            "note: {} holds files squeal did not write; it was left in place",
            p.display()
        );
    }
}

/// Whether `root/rel` is reached without passing through a symbolic link
/// (so that removing it cannot touch anything outside `root`).
fn no_link_on_the_way(root: &Path, rel: &str) -> bool {
    let mut cur = root.to_path_buf();
    let parts: Vec<&str> = rel.split('/').collect();
    for part in &parts[..parts.len().saturating_sub(1)] {
        cur.push(part);
        match std::fs::symlink_metadata(&cur) {
            Ok(m) if m.is_dir() => {}
            _ => return false,
        }
    }
    true
}

/// One entry of a folder tree, relative to its root ('/'-separated).
struct Entry {
    rel: String,
    is_dir: bool,
}

/// Every entry below `root` (not following links), sorted.
fn walk(root: &Path) -> std::io::Result<Vec<Entry>> {
    let mut out = Vec::new();
    let mut stack = vec![(root.to_path_buf(), String::new())];
    while let Some((dir, prefix)) = stack.pop() {
        for e in std::fs::read_dir(&dir)? {
            let e = e?;
            let name = e.file_name().to_string_lossy().into_owned();
            let rel = if prefix.is_empty() {
                name
            } else {
                format!("{prefix}/{name}")
            };
            let is_dir = e.file_type()?.is_dir();
            if is_dir {
                stack.push((e.path(), rel.clone()));
            }
            out.push(Entry { rel, is_dir });
        }
    }
    out.sort_by(|a, b| a.rel.cmp(&b.rel));
    Ok(out)
}

/// A relative path without `..`, root or prefix: safe to join to a folder.
fn is_plain_relative(rel: &str) -> bool {
    !rel.is_empty()
        && Path::new(rel)
            .components()
            .all(|c| matches!(c, Component::Normal(_)))
}

/// The files a folder's manifest lists: `Ok(None)` if it has none, an error
/// if it has one that is not a valid squeal manifest.
fn read_manifest(dir: &Path) -> Result<Option<Vec<String>>, String> {
    let path = dir.join(MANIFEST);
    match std::fs::symlink_metadata(&path) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        _ => {}
    }
    let text = squeal_study::input::read_regular_text(&path, squeal_study::input::MAX_RECORD_BYTES)
        .map_err(|e| format!("{MANIFEST}: {e}"))?;
    let v: Value =
        serde_json::from_str(&text).map_err(|_| format!("{MANIFEST} is not a squeal manifest"))?;
    let files = v["files"]
        .as_array()
        .filter(|_| v["written_by"] == "squeal")
        .ok_or_else(|| format!("{MANIFEST} is not a squeal manifest"))?;
    let mut out = Vec::with_capacity(files.len());
    for f in files {
        match f.as_str() {
            Some(s) if is_plain_relative(s) && s != MANIFEST => out.push(s.to_string()),
            _ => {
                return Err(format!(
                    "{MANIFEST} lists {f}, not a file inside the folder"
                ))
            }
        }
    }
    Ok(Some(out))
}

/// Write the manifest of `dir`: every file in it, sorted (so it is the same
/// for the same output).
fn write_manifest(dir: &Path) -> Result<(), RunError> {
    let files: Vec<String> = walk(dir)
        .map_err(|e| RunError::Io(format!("cannot list {}: {e}", dir.display())))?
        .into_iter()
        .filter(|e| !e.is_dir && e.rel != MANIFEST)
        .map(|e| e.rel)
        .collect();
    write_listed(dir, &files)
}

fn refuse(flag: &str, p: &Path, why: impl std::fmt::Display) -> RunError {
    RunError::Input(InputError(format!("{flag} {}: {why}", p.display())))
}

/// Check, before any work, that squeal may write the folder `dest` (chosen
/// by `flag`): it does not exist, or it is an empty folder, or a folder
/// whose manifest lists everything in it. Anything else — a file, a link,
/// the current folder, a folder holding something squeal did not write — is
/// refused, naming it.
pub fn check_dest_as(flag: &str, dest: &Path) -> Result<(), RunError> {
    // `link/` would make lstat follow the link: look at the name itself.
    let dest = &without_trailing_slash(dest);
    let last = dest.components().next_back();
    if !matches!(last, Some(Component::Normal(_))) {
        return Err(refuse(
            flag,
            dest,
            "name a folder of its own (squeal replaces it whole)",
        ));
    }
    let meta = match std::fs::symlink_metadata(dest) {
        Ok(m) => m,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(()),
        Err(e) => return Err(refuse(flag, dest, format!("cannot read it: {e}"))),
    };
    if meta.file_type().is_symlink() {
        return Err(refuse(
            flag,
            dest,
            "is a symbolic link; squeal does not write through links (name the folder itself)",
        ));
    }
    if !meta.is_dir() {
        return Err(refuse(flag, dest, "exists and is not a folder"));
    }
    let listed = read_manifest(dest).map_err(|e| refuse(flag, dest, e))?;
    let Some(listed) = listed else {
        // Not squeal's: name its first entry (by name) without descending
        // into it (it may be a home folder).
        let cannot = |e: std::io::Error| refuse(flag, dest, format!("cannot read it: {e}"));
        let mut names = std::fs::read_dir(dest)
            .map_err(cannot)?
            .map(|e| e.map(|e| e.file_name().to_string_lossy().into_owned()))
            .collect::<Result<Vec<_>, _>>()
            .map_err(cannot)?;
        names.sort();
        return match names.first() {
            None => Ok(()),
            Some(first) => Err(refuse(
                flag,
                dest,
                format!(
                    "holds '{first}' but no {MANIFEST}: not a folder squeal wrote; refusing to replace it"
                ),
            )),
        };
    };
    let entries = walk(dest).map_err(|e| refuse(flag, dest, format!("cannot read it: {e}")))?;
    let owns = |e: &Entry| {
        if e.is_dir {
            let prefix = format!("{}/", e.rel);
            listed.iter().any(|f| f.starts_with(&prefix))
        } else {
            e.rel == MANIFEST || listed.contains(&e.rel)
        }
    };
    if let Some(foreign) = entries.iter().find(|e| !owns(e)) {
        return Err(refuse(
            flag,
            dest,
            format!(
                "holds '{}', which squeal did not write; move it out of the folder and run again \
                 (squeal replaces only what it wrote)",
                foreign.rel
            ),
        ));
    }
    Ok(())
}

/// `p` without a trailing `/` (or `/.`), so that `symlink_metadata` looks
/// at a link rather than through it.
fn without_trailing_slash(p: &Path) -> PathBuf {
    p.components().collect()
}

/// Refuse a folder squeal is to write into (`plot`'s run folder) that is
/// itself a symbolic link; links among its ancestors (a linked scratch
/// folder) are fine.
pub fn check_not_a_link(what: &str, dir: &Path) -> Result<(), RunError> {
    let dir = without_trailing_slash(dir);
    match std::fs::symlink_metadata(&dir) {
        Ok(m) if m.file_type().is_symlink() => Err(refuse(
            what,
            &dir,
            "is a symbolic link; squeal does not write through links (name the folder itself)",
        )),
        _ => Ok(()),
    }
}

/// Folders to create so that `dir` exists, outermost first.
fn missing_ancestors(dir: &Path) -> Vec<PathBuf> {
    let mut missing = Vec::new();
    let mut cur = Some(dir);
    while let Some(d) = cur.filter(|d| !d.as_os_str().is_empty()) {
        if std::fs::symlink_metadata(d).is_ok() {
            break;
        }
        missing.push(d.to_path_buf());
        cur = d.parent();
    }
    missing.reverse();
    missing
}

/// An output folder written under a temporary name beside its destination
/// and swapped into place by [`Staging::commit`]; dropped uncommitted (or
/// interrupted), it is removed, with any parent folders it created.
pub struct Staging {
    tmp: PathBuf,
    dest: PathBuf,
    flag: String,
    created: Vec<PathBuf>,
    done: bool,
}

impl Staging {
    /// Stage output for `dest` (checked by [`check_dest_as`]) — before the work,
    /// so that an unwritable destination is found at once.
    pub fn new(dest: &Path) -> Result<Staging, RunError> {
        Staging::new_as("--out", dest)
    }

    /// Stage a command's output folder: `out` (its `--out`), or else
    /// `out/<default_name>`, named "output folder (default --out)" in messages.
    pub fn for_out(out: Option<&Path>, default_name: &str) -> Result<Staging, RunError> {
        match out {
            Some(dest) => Staging::new_as("--out", dest),
            None => Staging::new_as(
                "output folder (default --out)",
                &Path::new("out").join(default_name),
            ),
        }
    }

    /// [`Staging::new`] naming the flag that chose `dest` in messages.
    pub fn new_as(flag: &str, dest: &Path) -> Result<Staging, RunError> {
        let dest = &without_trailing_slash(dest);
        check_dest_as(flag, dest)?;
        let parent = parent_of(dest);
        let created = missing_ancestors(parent);
        let s = Staging {
            tmp: stage_path(dest, "new"),
            dest: dest.to_path_buf(),
            flag: flag.to_string(),
            created: created.clone(),
            done: false,
        };
        make_parent(parent, &created)?;
        make_stage(&s.tmp, created)?;
        Ok(s)
    }
    /// A scratch folder beside `dir`, removed when dropped (never committed).
    pub fn scratch(dir: &Path) -> Result<Staging, RunError> {
        let parent = parent_of(dir);
        let s = Staging {
            tmp: stage_path(dir, "new"),
            dest: dir.to_path_buf(),
            flag: String::new(),
            created: Vec::new(),
            done: false,
        };
        clean_stale(parent);
        make_stage(&s.tmp, Vec::new())?;
        Ok(s)
    }
    /// Path of a file inside the staging folder.
    pub fn path(&self, file: &str) -> PathBuf {
        self.tmp.join(file)
    }
    /// The staging folder.
    pub fn dir(&self) -> &Path {
        &self.tmp
    }
    /// Write the manifest and swap the complete output into place
    /// (replacing an older output of squeal's, which is then removed).
    pub fn commit(mut self) -> Result<PathBuf, RunError> {
        let _ = std::fs::remove_file(self.tmp.join(STAGE_MARKER));
        write_manifest(&self.tmp)?;
        let mut live = live();
        // The destination may have changed while the work ran.
        check_dest_as(&self.flag, &self.dest)?;
        let io = |e: std::io::Error| {
            RunError::Io(format!(
                "cannot move output into {}: {e}",
                self.dest.display()
            ))
        };
        let mut exists = std::fs::symlink_metadata(&self.dest).is_ok();
        if !exists {
            match rename_noreplace(&self.tmp, &self.dest) {
                Ok(()) => {}
                // Another run put it there meanwhile: check it, then swap.
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {
                    check_dest_as(&self.flag, &self.dest)?;
                    exists = true;
                }
                Err(e) => return Err(io(e)),
            }
        }
        if exists {
            if exchange(&self.tmp, &self.dest).map_err(io)? {
                // The old output is now at the staging name.
                remove_owned(&self.tmp);
            } else {
                let old = stage_path(&self.dest, "old");
                std::fs::rename(&self.dest, &old).map_err(io)?;
                if let Err(e) = std::fs::rename(&self.tmp, &self.dest) {
                    let _ = std::fs::rename(&old, &self.dest);
                    return Err(io(e));
                }
                remove_owned(&old);
            }
        }
        forget(&mut live, &self.tmp);
        self.done = true;
        Ok(self.dest.clone())
    }
}

impl Drop for Staging {
    fn drop(&mut self) {
        if self.done {
            return;
        }
        let mut live = live();
        remove_partial(&self.tmp);
        forget(&mut live, &self.tmp);
        remove_created(&self.created);
    }
}

/// Swap `a` and `b` atomically; `Ok(false)` where the system cannot.
fn exchange(a: &Path, b: &Path) -> std::io::Result<bool> {
    #[cfg(any(target_os = "linux", target_os = "android"))]
    {
        use rustix::fs::{renameat_with, RenameFlags, CWD};
        match renameat_with(CWD, a, CWD, b, RenameFlags::EXCHANGE) {
            Ok(()) => Ok(true),
            Err(e) if e == rustix::io::Errno::INVAL || e == rustix::io::Errno::NOSYS => Ok(false),
            Err(e) => Err(e.into()),
        }
    }
    #[cfg(not(any(target_os = "linux", target_os = "android")))]
    {
        let _ = (a, b);
        Ok(false)
    }
}

/// Rename `a` to `b`, failing if `b` exists (where the system can tell).
fn rename_noreplace(a: &Path, b: &Path) -> std::io::Result<()> {
    #[cfg(any(target_os = "linux", target_os = "android"))]
    {
        use rustix::fs::{renameat_with, RenameFlags, CWD};
        match renameat_with(CWD, a, CWD, b, RenameFlags::NOREPLACE) {
            Ok(()) => return Ok(()),
            Err(e) if e == rustix::io::Errno::INVAL || e == rustix::io::Errno::NOSYS => {}
            Err(e) => return Err(e.into()),
        }
    }
    std::fs::rename(a, b)
}

/// A single output file (`listen --out`) written under a temporary name
/// beside it and renamed into place by [`StagedFile::commit`]. An existing
/// file is replaced only with `force`; folders and links never.
pub struct StagedFile {
    /// The marked staging folder beside `dest`.
    dir: PathBuf,
    /// The file written inside it.
    tmp: PathBuf,
    dest: PathBuf,
    force: bool,
    created: Vec<PathBuf>,
    done: bool,
}

/// Check that squeal may write the single file `dest` (flag `flag`).
pub fn check_file(flag: &str, dest: &Path, force: bool) -> Result<(), RunError> {
    let dest = &without_trailing_slash(dest);
    if !matches!(dest.components().next_back(), Some(Component::Normal(_))) {
        return Err(refuse(flag, dest, "name a file"));
    }
    match std::fs::symlink_metadata(dest) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(()),
        Err(e) => Err(refuse(flag, dest, format!("cannot read it: {e}"))),
        Ok(m) if m.file_type().is_symlink() => Err(refuse(
            flag,
            dest,
            "is a symbolic link; squeal does not write through links",
        )),
        Ok(m) if m.is_dir() => Err(refuse(flag, dest, "is a folder; name a file")),
        Ok(m) if !m.is_file() => Err(refuse(
            flag,
            dest,
            format!(
                "is {}, not a regular file; squeal replaces only regular files, even with --force",
                squeal_study::input::kind_of(m.file_type())
            ),
        )),
        Ok(_) if force => Ok(()),
        Ok(_) => Err(refuse(
            flag,
            dest,
            "exists; squeal does not overwrite a file (choose another name, or --force to replace it)",
        )),
    }
}

impl StagedFile {
    /// Stage the file `dest` (checked by [`check_file`]).
    pub fn new(flag: &str, dest: &Path, force: bool) -> Result<StagedFile, RunError> {
        check_file(flag, dest, force)?;
        let parent = parent_of(dest);
        let created = missing_ancestors(parent);
        make_parent(parent, &created)?;
        let dir = stage_path(dest, "new");
        make_stage(&dir, created.clone())?;
        let tmp = dir.join(dest.file_name().unwrap_or(std::ffi::OsStr::new("file")));
        let staged = StagedFile {
            dir,
            tmp,
            dest: dest.to_path_buf(),
            force,
            created,
            done: false,
        };
        std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&staged.tmp)
            .map_err(|e| RunError::Io(format!("cannot write into {}: {e}", parent.display())))?;
        Ok(staged)
    }
    /// The temporary file to write.
    pub fn path(&self) -> &Path {
        &self.tmp
    }
    /// Rename the complete file into place.
    pub fn commit(mut self, flag: &str) -> Result<PathBuf, RunError> {
        let mut live = live();
        check_file(flag, &self.dest, self.force)?;
        let io =
            |e: std::io::Error| RunError::Io(format!("cannot write {}: {e}", self.dest.display()));
        if self.force {
            std::fs::rename(&self.tmp, &self.dest).map_err(io)?;
        } else {
            rename_noreplace(&self.tmp, &self.dest).map_err(io)?;
        }
        remove_partial(&self.dir);
        forget(&mut live, &self.dir);
        self.done = true;
        Ok(self.dest.clone())
    }
}

impl Drop for StagedFile {
    fn drop(&mut self) {
        if !self.done {
            let mut live = live();
            remove_partial(&self.dir);
            forget(&mut live, &self.dir);
            remove_created(&self.created);
        }
    }
}

/// Replace files of an existing squeal output folder in place (`plot`):
/// `staged` holds the new files; each may replace only a file the folder's
/// manifest lists (or none); the manifest then lists the new ones too.
pub fn replace_files(dir: &Path, staged: &Path) -> Result<(), RunError> {
    check_not_a_link("run folder", dir)?;
    let manifest = read_manifest(dir).map_err(|e| refuse("run folder", dir, e))?;
    let why = if manifest.is_some() {
        "which squeal did not write".to_string()
    } else {
        format!("and no {MANIFEST} says squeal wrote it (an older squeal's run? simulate again)")
    };
    let listed = manifest.unwrap_or_default();
    let new: Vec<String> = walk(staged)
        .map_err(|e| RunError::Io(format!("cannot list {}: {e}", staged.display())))?
        .into_iter()
        .filter(|e| !e.is_dir && e.rel != STAGE_MARKER)
        .map(|e| e.rel)
        .collect();
    for f in &new {
        let target = dir.join(f);
        if std::fs::symlink_metadata(&target).is_ok() && !listed.contains(f) {
            return Err(refuse(
                "run folder",
                dir,
                format!("holds '{f}', {why}; refusing to replace it"),
            ));
        }
    }
    // The manifest first, then the files, under the lock the signal handler
    // takes: an interrupt waits, and a crash midway leaves no file of
    // squeal's unlisted (which would block the next run).
    let _live = live();
    let mut all = listed;
    all.extend(new.iter().cloned());
    write_listed(dir, &all)?;
    for f in &new {
        std::fs::rename(staged.join(f), dir.join(f))
            .map_err(|e| RunError::Io(format!("cannot write {}: {e}", dir.join(f).display())))?;
    }
    Ok(())
}

/// Write `dir`'s manifest listing exactly `files`.
fn write_listed(dir: &Path, files: &[String]) -> Result<(), RunError> {
    let mut files = files.to_vec();
    files.sort();
    files.dedup();
    let doc = json!({
        "written_by": "squeal",
        "note": "squeal replaces this folder only while it holds nothing but these files",
        "files": files,
    });
    let mut text = serde_json::to_string_pretty(&doc).map_err(|e| RunError::Io(e.to_string()))?;
    text.push('\n');
    let path = dir.join(MANIFEST);
    if std::fs::symlink_metadata(&path).is_ok_and(|m| !m.is_file()) {
        return Err(refuse(
            "manifest",
            &path,
            "is not a regular file (a link?); squeal does not write through links",
        ));
    }
    std::fs::write(&path, text)
        .map_err(|e| RunError::Io(format!("cannot write {}: {e}", path.display())))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn staging_names_are_short_and_recognised() {
        let long = "x".repeat(255);
        let p = stage_path(Path::new(&long), "new");
        let name = p.file_name().unwrap().to_str().unwrap();
        assert!(name.len() < 64, "{name}");
        assert_eq!(stage_pid(name), Some(std::process::id()));
        assert_eq!(stage_pid(".squeal-12-0123456789abcdef.old"), Some(12));
        assert_eq!(stage_pid(".squeal-manifest.json"), None);
        assert_eq!(stage_pid(".squeal-12-0123.new"), None);
        assert!(alive(std::process::id()));
    }

    #[test]
    fn removal_never_follows_a_link_out_of_the_folder() {
        let d = tempfile::tempdir().unwrap();
        let outside = d.path().join("outside");
        std::fs::create_dir(&outside).unwrap();
        std::fs::write(outside.join("a.png"), "precious").unwrap();
        let stale = d.path().join(".squeal-1-0123456789abcdef.old");
        std::fs::create_dir(&stale).unwrap();
        std::os::unix::fs::symlink(&outside, stale.join("figures")).unwrap();
        std::fs::write(stale.join("b.csv"), "x").unwrap();
        write_listed(&stale, &["figures/a.png".into(), "b.csv".into()]).unwrap();
        assert!(!no_link_on_the_way(&stale, "figures/a.png"));
        remove_owned(&stale);
        assert!(outside.join("a.png").is_file());
        assert!(!stale.join("b.csv").exists());
    }

    #[test]
    fn manifests_list_only_paths_inside_the_folder() {
        assert!(is_plain_relative("figures/a.png"));
        for bad in ["", "../x", "/etc/passwd", "a/../../b", "."] {
            assert!(!is_plain_relative(bad), "{bad}");
        }
    }
}
