//! Reading the files a user names (issue 24, class 3): only regular files
//! are read — a character device, FIFO, socket or folder is refused by
//! name — except a scenario, which may also come from a pipe
//! (`squeal simulate <(…)`). Every input has a size limit, checked from the
//! file's size before reading and again while reading (a file that grows
//! stops at the limit), and a pipe has a timeout.
//!
//! The file is opened without blocking (`O_NONBLOCK`: opening a FIFO that
//! nobody writes returns at once) and what was opened is then looked at
//! (`fstat` on the open file, so a file swapped between a check and the
//! open is still caught). Hand-written because no crate does "open, then
//! refuse anything but a regular file, then read at most n bytes, with a
//! timeout for pipes" in one step; it is a few system calls on `rustix`.

use std::fs::File;
use std::io::Read;
use std::os::unix::fs::{FileTypeExt, OpenOptionsExt};
use std::path::Path;
use std::time::{Duration, Instant};

/// Most bytes of a scenario file (64 MiB: a scenario is a few kB, but an
/// FE brake's lists every dof by name, ~15 MB for 10⁶ dofs).
pub const MAX_SCENARIO_BYTES: u64 = 64 << 20;

/// Most bytes of one matrix file (4 GiB: an FE export of 10⁶ dofs with
/// 10⁸ entries is a few GB of text).
pub const MAX_MATRIX_BYTES: u64 = 4 << 30;

/// Most bytes of a shard's small records (`shard.json`, a run's
/// `summary.json`, `manifest.json`): 64 MiB.
pub const MAX_RECORD_BYTES: u64 = 64 << 20;

/// Most bytes of a table squeal reads back (`part.csv` of a shard, a run's
/// series for `plot` and `listen`, `events.csv`): 4 GB, the size squeal
/// itself refuses to write (see the README).
pub const MAX_TABLE_BYTES: u64 = 4_000_000_000;

/// How long a scenario pipe may stay silent before the read gives up.
pub const PIPE_TIMEOUT: Duration = Duration::from_secs(10);

/// What a path turned out to be, in words for a message.
pub fn kind_of(t: std::fs::FileType) -> &'static str {
    if t.is_dir() {
        "a folder"
    } else if t.is_char_device() {
        "a character device"
    } else if t.is_block_device() {
        "a block device"
    } else if t.is_fifo() {
        "a pipe (FIFO)"
    } else if t.is_socket() {
        "a socket"
    } else if t.is_symlink() {
        "a symbolic link"
    } else {
        "not a regular file"
    }
}

/// Binary prefix size for messages ("4 GiB", "1 MiB", "12.3 kB").
pub fn size_words(bytes: u64) -> String {
    const UNITS: [(u64, &str); 3] = [(1 << 30, "GiB"), (1 << 20, "MiB"), (1 << 10, "KiB")];
    for (u, name) in UNITS {
        if bytes >= u {
            let x = bytes as f64 / u as f64;
            return if bytes.is_multiple_of(u) {
                format!("{} {name}", bytes / u)
            } else {
                format!("{x:.1} {name}")
            };
        }
    }
    format!("{bytes} bytes")
}

/// Open `path` without blocking and say what it is.
fn open(path: &Path) -> Result<(File, std::fs::Metadata), String> {
    let file = std::fs::OpenOptions::new()
        .read(true)
        .custom_flags(rustix::fs::OFlags::NONBLOCK.bits() as i32)
        .open(path)
        .map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    let meta = file
        .metadata()
        .map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    Ok((file, meta))
}

fn too_big(path: &Path, limit: u64) -> String {
    format!(
        "{} is larger than the {} limit for this input",
        path.display(),
        size_words(limit)
    )
}

/// Read a regular file of at most `limit` bytes. Anything else (a device,
/// FIFO, socket or folder) is refused without reading it.
pub fn read_regular(path: &Path, limit: u64) -> Result<Vec<u8>, String> {
    let (file, meta) = open(path)?;
    if !meta.file_type().is_file() {
        return Err(format!(
            "{} is {}, not a regular file; squeal reads only regular files here",
            path.display(),
            kind_of(meta.file_type())
        ));
    }
    if meta.len() > limit {
        return Err(too_big(path, limit));
    }
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    file.take(limit + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    if bytes.len() as u64 > limit {
        return Err(too_big(path, limit));
    }
    Ok(bytes)
}

fn utf8(path: &Path, bytes: Vec<u8>) -> Result<String, String> {
    String::from_utf8(bytes).map_err(|e| {
        format!(
            "{}: not UTF-8 text (byte {} is invalid)",
            path.display(),
            e.utf8_error().valid_up_to() + 1
        )
    })
}

/// [`read_regular`] as UTF-8 text.
pub fn read_regular_text(path: &Path, limit: u64) -> Result<String, String> {
    utf8(path, read_regular(path, limit)?)
}

/// Whether `path` names something other than a folder (a file, a pipe
/// such as the `/dev/fd/63` of `squeal simulate <(…)`, or a device, which
/// the reader then refuses by name).
pub fn names_a_non_folder(path: &Path) -> bool {
    std::fs::metadata(path).is_ok_and(|m| !m.is_dir())
}

/// Read a scenario: a regular file, or a pipe read until its writer closes
/// it, at most `limit` bytes, and giving up when no byte arrives for
/// `timeout`.
pub fn read_text_or_pipe(path: &Path, limit: u64, timeout: Duration) -> Result<String, String> {
    let (mut file, meta) = open(path)?;
    if meta.file_type().is_file() {
        drop(file);
        return read_regular_text(path, limit);
    }
    if !meta.file_type().is_fifo() {
        return Err(format!(
            "{} is {}, not a regular file or a pipe",
            path.display(),
            kind_of(meta.file_type())
        ));
    }
    use rustix::event::{poll, PollFd, PollFlags, Timespec};
    let mut bytes = Vec::new();
    let mut chunk = [0u8; 64 * 1024];
    let mut last = Instant::now();
    loop {
        let left = timeout.saturating_sub(last.elapsed());
        if left.is_zero() {
            return Err(format!(
                "{}: nothing arrived from the pipe for {} s",
                path.display(),
                timeout.as_secs()
            ));
        }
        let ts = Timespec {
            tv_sec: left.as_secs() as i64,
            tv_nsec: left.subsec_nanos() as _,
        };
        let mut fds = [PollFd::new(&file, PollFlags::IN)];
        match poll(&mut fds, Some(&ts)) {
            Ok(0) => continue,
            Ok(_) => {}
            Err(rustix::io::Errno::INTR) => continue,
            Err(e) => return Err(format!("cannot read {}: {e}", path.display())),
        }
        let ready = fds[0].revents();
        if !ready.intersects(PollFlags::IN | PollFlags::HUP | PollFlags::ERR) {
            continue;
        }
        match file.read(&mut chunk) {
            Ok(0) => break,
            Ok(n) => {
                bytes.extend_from_slice(&chunk[..n]);
                if bytes.len() as u64 > limit {
                    return Err(too_big(path, limit));
                }
                last = Instant::now();
            }
            Err(e)
                if e.kind() == std::io::ErrorKind::WouldBlock
                    || e.kind() == std::io::ErrorKind::Interrupted =>
            {
                // A hang-up with nothing to read is the end; otherwise wait.
                if ready.contains(PollFlags::HUP) {
                    break;
                }
            }
            Err(e) => return Err(format!("cannot read {}: {e}", path.display())),
        }
    }
    utf8(path, bytes)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_read_as_words() {
        assert_eq!(size_words(4 << 30), "4 GiB");
        assert_eq!(size_words(1 << 20), "1 MiB");
        assert_eq!(size_words(1536), "1.5 KiB");
        assert_eq!(size_words(12), "12 bytes");
    }

    #[test]
    fn devices_and_folders_are_refused_by_name() {
        let e = read_regular(Path::new("/dev/zero"), 1 << 20).unwrap_err();
        assert!(e.contains("/dev/zero is a character device"), "{e}");
        let e = read_regular(Path::new("/"), 1 << 20).unwrap_err();
        assert!(e.contains("is a folder"), "{e}");
        let e = read_text_or_pipe(Path::new("/dev/zero"), 1 << 20, PIPE_TIMEOUT).unwrap_err();
        assert!(e.contains("character device"), "{e}");
    }
}
