//! What every fuzz target shares: the loop that takes inputs from AFL++ (or from files, to
//! replay a corpus or a crash), the heap bound every input is held to, and the checks on
//! what a reader returns. docs/FUZZING.md says how the targets are built and run.
//!
//! A finding is anything that aborts the process: a panic (the profile sets
//! `panic = "abort"`), a failed check here, or a heap bound exceeded.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::RefCell;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::OnceLock;

use ferrovol_core::{UnstructuredVolume, VolumeData};
use ferrovol_io::ReadError;

// AFL++'s runtime, afl-compiler-rt.o, which scripts/fuzz.sh links in. Under afl-fuzz it
// maps the coverage and input shared memory and runs the fork server from a constructor.
extern "C" {
    fn __afl_persistent_loop(max_count: u32) -> i32;
    static __afl_fuzz_ptr: *const u8;
    static __afl_fuzz_len: *const u32;
}

/// Tells AFL++'s runtime that this program takes its inputs from shared memory
/// (`__afl_fuzz_ptr`) when afl-fuzz offers them there.
#[no_mangle]
pub static mut __afl_sharedmem_fuzzing: i32 = 1;

/// afl-fuzz looks for this signature in the binary and then runs it in persistent mode:
/// many inputs per process, each `__afl_persistent_loop` iteration one input.
static PERSISTENT_SIGNATURE: &[u8] = b"##SIG_AFL_PERSISTENT##\0";

/// Inputs one process runs before afl-fuzz starts a fresh one.
const INPUTS_PER_PROCESS: u32 = 100_000;

/// The heap an input of `len` bytes may make the process hold, above what it held before
/// the input: 1 MiB, plus 8 × 1032 bytes per input byte. 1032 is deflate's largest
/// expansion (zlib and gzip data), 8 the copies a reader may hold at once (inflated
/// bytes, decoded values, values scaled to float, interleaved values, growth slack). A
/// reader that allocates what a header claims before checking the data is there exceeds
/// it: a 300-byte header may not make the reader hold more than 3.5 MiB.
fn heap_bound(len: usize) -> usize {
    (1usize << 20).saturating_add(len.saturating_mul(8 * 1032))
}

/// Bytes the process holds on the heap now.
static LIVE: AtomicUsize = AtomicUsize::new(0);
/// The most it may hold while an input runs (`usize::MAX` between inputs).
static LIMIT: AtomicUsize = AtomicUsize::new(usize::MAX);

/// The system allocator, counting live bytes and aborting when an input's heap bound is
/// exceeded.
struct Bounded;

impl Bounded {
    fn grow(size: usize) {
        let live = LIVE.fetch_add(size, Ordering::Relaxed).saturating_add(size);
        let limit = LIMIT.load(Ordering::Relaxed);
        if live > limit {
            // Lift the limit first: the message itself may allocate.
            LIMIT.store(usize::MAX, Ordering::Relaxed);
            eprintln!(
                "heap bound exceeded: {live} bytes live after a request of {size} bytes, bound {limit} (fuzz/src/lib.rs, heap_bound)"
            );
            std::process::abort();
        }
    }

    fn shrink(size: usize) {
        LIVE.fetch_sub(size, Ordering::Relaxed);
    }
}

// SAFETY: every call is passed on to `System` unchanged; only counters are added.
unsafe impl GlobalAlloc for Bounded {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        Self::grow(layout.size());
        System.alloc(layout)
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        Self::grow(layout.size());
        System.alloc_zeroed(layout)
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        Self::shrink(layout.size());
        System.dealloc(ptr, layout)
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        if new_size > layout.size() {
            Self::grow(new_size - layout.size());
        } else {
            Self::shrink(layout.size() - new_size);
        }
        System.realloc(ptr, layout, new_size)
    }
}

#[global_allocator]
static ALLOCATOR: Bounded = Bounded;

/// Runs `target` on each input, holding it to [`heap_bound`]. `target` returns a line
/// saying what the input gave, which replays print.
///
/// * With file arguments: runs each file (a corpus, a crash to reproduce) and prints its
///   line.
/// * Under afl-fuzz: persistent mode, inputs from shared memory.
/// * Otherwise: one input from stdin.
pub fn fuzz(target: fn(&[u8]) -> String) {
    // Keeps the signature in the binary.
    std::hint::black_box(PERSISTENT_SIGNATURE.as_ptr());
    // The panic message and backtrace are not the input's allocations.
    let report = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        LIMIT.store(usize::MAX, Ordering::Relaxed);
        report(info);
    }));
    let files: Vec<PathBuf> = std::env::args_os().skip(1).map(PathBuf::from).collect();
    if !files.is_empty() {
        for file in files {
            match std::fs::read(&file) {
                Ok(bytes) => println!("{}: {}", file.display(), run(target, &bytes)),
                Err(e) => {
                    eprintln!("{}: cannot read the input: {e}", file.display());
                    std::process::exit(2);
                }
            }
        }
        return;
    }
    // SAFETY: the runtime sets the pointer (or leaves it null) before main runs.
    if unsafe { __afl_fuzz_ptr.is_null() } {
        let mut input = Vec::new();
        if let Err(e) = std::io::stdin().read_to_end(&mut input) {
            eprintln!("cannot read the input from stdin: {e}");
            std::process::exit(2);
        }
        println!("{}", run(target, &input));
        return;
    }
    // SAFETY: in each iteration the runtime has placed the input at `__afl_fuzz_ptr`,
    // `*__afl_fuzz_len` bytes long, and leaves it there until the next iteration.
    while unsafe { __afl_persistent_loop(INPUTS_PER_PROCESS) } != 0 {
        let input = unsafe { std::slice::from_raw_parts(__afl_fuzz_ptr, *__afl_fuzz_len as usize) };
        run(target, input);
    }
}

/// Runs one input under its heap bound.
fn run(target: fn(&[u8]) -> String, input: &[u8]) -> String {
    let before = LIVE.load(Ordering::Relaxed);
    LIMIT.store(
        before.saturating_add(heap_bound(input.len())),
        Ordering::Relaxed,
    );
    let line = target(input);
    LIMIT.store(usize::MAX, Ordering::Relaxed);
    line
}

/// Checks what a volume reader returned: a volume must pass `validate` (the readers
/// promise that), an error must have a message. Returns the input's line.
pub fn check_volume(result: &Result<VolumeData, ReadError>) -> String {
    match result {
        Ok(v) => {
            if let Err(e) = v.validate() {
                panic!("a reader returned a volume that fails validation: {e}");
            }
            format!(
                "volume {}x{}x{}, {} component(s) of {}",
                v.dims[0],
                v.dims[1],
                v.dims[2],
                v.components,
                v.scalars.scalar_type().name()
            )
        }
        Err(e) => error_line(e),
    }
}

/// [`check_volume`] for a mesh reader: the mesh must pass validation; an error must
/// have a message.
pub fn check_mesh(result: &Result<UnstructuredVolume, ReadError>) -> String {
    match result {
        Ok(m) => {
            if let Err(e) = m.validate() {
                panic!("a reader returned a mesh that fails validation: {e}");
            }
            format!(
                "mesh of {} points and {} cells, {} component(s) of {}",
                m.points.len(),
                m.num_cells(),
                m.components,
                m.scalar_type().name()
            )
        }
        Err(e) => error_line(e),
    }
}

/// The line for an error, which must have a message.
fn error_line(e: &ReadError) -> String {
    let message = e.to_string();
    assert!(!message.is_empty(), "an error without a message: {e:?}");
    format!("error: {message}")
}

/// Separates the bytes of a header from those of its detached data file: an input holds
/// both, the data file after the first [`DATA_FILE_MARK`]. Without a mark the input is
/// all header and has no data file.
fn split_data_file(input: &[u8]) -> (&[u8], Option<&[u8]>) {
    match input
        .windows(DATA_FILE_MARK.len())
        .position(|w| w == DATA_FILE_MARK)
    {
        Some(i) => (&input[..i], Some(&input[i + DATA_FILE_MARK.len()..])),
        None => (input, None),
    }
}

/// The line that separates a header from its detached data file in an input.
const DATA_FILE_MARK: &[u8] = b"\n#ferrovol-fuzz data file\n";

/// Parses a MetaImage or NRRD input (header, then maybe a data file after
/// [`DATA_FILE_MARK`]) with `format`: whatever name the header gives its data file gets
/// the input's data file. A volume that parses is also read from files, `header_name`
/// and the data file, by [`check_files`].
pub fn parse_with_data_file(
    format: ferrovol_io::Format,
    input: &[u8],
    header_name: &str,
) -> String {
    let (header, data) = split_data_file(input);
    let asked = RefCell::new(None);
    let result = format.parse(header, |name| {
        *asked.borrow_mut() = Some(name.to_string());
        match data {
            Some(d) => Ok(d.to_vec()),
            None => ferrovol_io::no_data_file(name),
        }
    });
    let line = check_volume(&result);
    if let Ok(volume) = &result {
        let detached = asked.into_inner().zip(data);
        check_files(header, header_name, detached, volume);
    }
    line
}

/// A folder of this process's own for [`check_files`].
fn scratch() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let dir = std::env::temp_dir().join(format!("ferrovol-fuzz-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("a scratch folder in the temp dir");
        dir
    })
}

/// Writes a header that parsed to `parsed` (and its data file, as the header names it) to
/// files and checks the path API against the byte-slice API: `read_volume` returns the
/// same volume, `open_volume` (raw data read in place) one with the same geometry and
/// values. Skipped when the data file's name is not a plain file name, which would put
/// it outside the scratch folder.
fn check_files(
    header: &[u8],
    header_name: &str,
    data_file: Option<(String, &[u8])>,
    parsed: &VolumeData,
) {
    let dir = scratch();
    if let Some((name, bytes)) = &data_file {
        let plain = !name.is_empty()
            && name.len() < 200
            && name != header_name
            && !matches!(name.as_str(), "." | "..")
            && !name.contains(['/', '\0']);
        if !plain {
            return;
        }
        std::fs::write(dir.join(name), bytes).expect("writing the data file");
    }
    let path = dir.join(header_name);
    std::fs::write(&path, header).expect("writing the header");

    let read = ferrovol_io::read_volume(&path)
        .unwrap_or_else(|e| panic!("parse returned a volume, read_volume failed: {e}"));
    assert_same(parsed, &read, "read_volume");
    let opened = ferrovol_io::open_volume(&path)
        .unwrap_or_else(|e| panic!("parse returned a volume, open_volume failed: {e}"));
    assert_same(parsed, &opened, "open_volume");
    if let Some((name, _)) = data_file {
        std::fs::remove_file(dir.join(name)).expect("removing the data file");
    }
}

/// Checks that `b` (from `api`) has `a`'s geometry, scalar type and values.
fn assert_same(a: &VolumeData, b: &VolumeData, api: &str) {
    let geometry = |v: &VolumeData| (v.dims, v.components, v.spacing, v.origin, v.direction);
    assert_eq!(geometry(a), geometry(b), "{api}: geometry differs");
    assert_eq!(
        a.scalars.scalar_type(),
        b.scalars.scalar_type(),
        "{api}: scalar type differs"
    );
    let values = |v: &VolumeData| {
        let mut out = vec![0.0; v.scalars.len()];
        v.scalars
            .read_run(0, &mut out)
            .unwrap_or_else(|e| panic!("{api}: reading the values failed: {e}"));
        out
    };
    // Validated volumes hold no NaN, so values compare exactly.
    assert!(values(a) == values(b), "{api}: values differ");
}
