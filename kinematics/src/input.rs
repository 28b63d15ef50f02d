//! Opening input files: scenarios, plans, robot descriptions and URDFs are
//! read only from regular files. A FIFO is refused before it is opened
//! (opening one waits for a writer that may never come), and so are devices
//! (`/dev/zero` never ends), folders and sockets, each named.

use std::path::Path;

/// Opens `path` for reading when it is a regular file (symlinks followed).
/// Anything else is refused before it is opened, with what it is: opening
/// a FIFO waits for a writer that may never come, a character device
/// (`/dev/zero`) never ends, a folder has no text.
pub fn open_regular(path: &Path) -> std::io::Result<std::fs::File> {
    let refuse = |kind: std::fs::FileType| {
        Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            format!(
                "is {}, not a regular file: afford reads its input from files",
                special_kind(kind)
            ),
        ))
    };
    let kind = std::fs::metadata(path)?.file_type();
    if !kind.is_file() {
        return refuse(kind);
    }
    let file = std::fs::File::open(path)?;
    // Swapped for something else between the look and the opening.
    match file.metadata()?.file_type() {
        kind if kind.is_file() => Ok(file),
        kind => refuse(kind),
    }
}

/// What a file that is not a regular file is, in words.
fn special_kind(kind: std::fs::FileType) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if kind.is_fifo() {
            return "a FIFO (named pipe)";
        }
        if kind.is_char_device() || kind.is_block_device() {
            return "a device";
        }
        if kind.is_socket() {
            return "a socket";
        }
    }
    match kind.is_dir() {
        true => "a folder",
        false => "a special file",
    }
}
