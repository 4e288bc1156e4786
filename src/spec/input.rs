//! Reading input files with a bound: every file the user hands in (specs, scene manifests, model
//! files, CSV data and profiles, shard files) is read through [`read_input`], which takes only
//! regular files (a device, FIFO or folder is refused before it is opened for reading, so
//! `/dev/zero` or a pipe cannot make a read run forever) and at most [`MAX_INPUT_BYTES`];
//! readers that bound their own reading (PNG maps, by their header's dimensions) open the file
//! through [`open_regular`].

use std::io::Read;
use std::path::Path;

/// The most bytes an input file may have: 64 MiB. The largest inputs are CSV data and shard
/// files; the bundled ones are well under 1 MiB, and 64 MiB of CSV is millions of rows.
pub const MAX_INPUT_BYTES: u64 = 64 << 20;

/// Why an input file was not read. The messages do not name the file: the caller does.
#[derive(Debug, thiserror::Error)]
pub enum ReadError {
    #[error("cannot read: {0}")]
    Io(#[from] std::io::Error),
    #[error("not a regular file ({0}); inputs are read from regular files only")]
    NotRegular(&'static str),
    #[error("{size} bytes or more, over the limit of {limit} bytes for an input file")]
    TooLarge { size: u64, limit: u64 },
    #[error("not UTF-8 text: {0}")]
    NotText(std::str::Utf8Error),
}

fn kind_of(m: &std::fs::Metadata) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        let t = m.file_type();
        if t.is_char_device() {
            return "a character device";
        }
        if t.is_block_device() {
            return "a block device";
        }
        if t.is_fifo() {
            return "a FIFO";
        }
        if t.is_socket() {
            return "a socket";
        }
    }
    if m.is_dir() { "a folder" } else { "not a plain file" }
}

/// The regular file `path` (symbolic links followed) opened for reading, with its length. The
/// type is checked before the file is opened (opening a FIFO would wait for a writer) and again
/// on the open file. For readers that bound what they read themselves (a PNG decoder, after
/// checking the image's header).
pub fn open_regular(path: &Path) -> Result<(std::fs::File, u64), ReadError> {
    let regular = |m: &std::fs::Metadata| if m.is_file() { Ok(()) } else { Err(ReadError::NotRegular(kind_of(m))) };
    regular(&std::fs::metadata(path)?)?;
    let file = std::fs::File::open(path)?;
    let meta = file.metadata()?;
    regular(&meta)?;
    Ok((file, meta.len()))
}

/// The bytes of the regular file `path` ([`open_regular`]), at most `limit` of them. The read
/// stops one byte past the limit, so a file that grows while it is read is refused too.
pub fn read_limited(path: &Path, limit: u64) -> Result<Vec<u8>, ReadError> {
    let (file, len) = open_regular(path)?;
    if len > limit {
        return Err(ReadError::TooLarge { size: len, limit });
    }
    let mut bytes = Vec::with_capacity(len as usize);
    file.take(limit + 1).read_to_end(&mut bytes)?;
    if bytes.len() as u64 > limit {
        return Err(ReadError::TooLarge { size: bytes.len() as u64, limit });
    }
    Ok(bytes)
}

/// [`read_limited`] to [`MAX_INPUT_BYTES`].
pub fn read_input(path: &Path) -> Result<Vec<u8>, ReadError> {
    read_limited(path, MAX_INPUT_BYTES)
}

/// [`read_input`] as UTF-8 text.
pub fn read_input_text(path: &Path) -> Result<String, ReadError> {
    String::from_utf8(read_input(path)?).map_err(|e| ReadError::NotText(e.utf8_error()))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A file of exactly the limit is read whole; one byte more is refused, naming the limit;
    /// a folder and (on Unix) /dev/zero are refused as not regular before any byte is read;
    /// invalid UTF-8 is refused as text.
    #[test]
    fn reads_regular_files_up_to_the_limit_only() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("f");
        std::fs::write(&p, b"0123456789").unwrap();
        assert_eq!(read_limited(&p, 10).unwrap(), b"0123456789");
        let e = read_limited(&p, 9).unwrap_err().to_string();
        assert_eq!(e, "10 bytes or more, over the limit of 9 bytes for an input file");
        let e = read_input(dir.path()).unwrap_err().to_string();
        assert!(e.starts_with("not a regular file (a folder)"), "{e}");
        #[cfg(unix)]
        {
            let e = read_input(Path::new("/dev/zero")).unwrap_err().to_string();
            assert!(e.starts_with("not a regular file (a character device)"), "{e}");
        }
        std::fs::write(&p, [0xff, 0xfe]).unwrap();
        assert!(matches!(read_input_text(&p), Err(ReadError::NotText(_))));
        assert!(matches!(read_input(&dir.path().join("absent")), Err(ReadError::Io(_))));
    }
}
