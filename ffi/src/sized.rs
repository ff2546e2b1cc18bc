//! Parameter structs that grow between minor versions. Each begins with `size`, the
//! struct's size as the caller's header declared it (`sizeof`), written by its
//! fv_*_default function. Fields are only ever appended, and no struct ends in padding, so
//! a caller's struct of `size` bytes holds exactly the fields its header knew: the library
//! reads those and gives every later field its default. A size below the first versioned
//! layout's, or above this library's (a program built against a newer header), is refused
//! with a message naming both.

use crate::{FfiError, FfiResult};

/// A C parameter struct with a leading `size` field (see the module documentation).
pub trait SizedParams: Copy {
    /// The struct's name in the header, for messages.
    const NAME: &'static str;
    /// Its size in the first version that carried `size` (0.2.0): the smallest accepted.
    const FIRST_SIZE: usize;
    /// Every field at its default.
    fn defaults() -> Self;
    fn set_size(&mut self, size: usize);
}

/// Checks a caller's `size` against what this library reads.
fn check_size<T: SizedParams>(size: usize) -> FfiResult<()> {
    let own = std::mem::size_of::<T>();
    if size < T::FIRST_SIZE || size > own || !size.is_multiple_of(std::mem::align_of::<T>()) {
        return Err(FfiError::invalid(format!(
            "{}.size is {size}: fill the struct with its fv_*_default function, passing \
             sizeof({}) (this library ({}) reads sizes {} to {own}; a larger size means a \
             program built against a newer ferrovol.h than the library it runs with)",
            T::NAME,
            T::NAME,
            env!("CARGO_PKG_VERSION"),
            T::FIRST_SIZE,
        )));
    }
    Ok(())
}

/// Writes the defaults into the caller's struct of `size` bytes, `size` included.
pub fn write_defaults<T: SizedParams>(p: *mut T, size: usize, what: &str) -> FfiResult<()> {
    if p.is_null() {
        return Err(FfiError::null(what));
    }
    check_size::<T>(size)?;
    let mut d = T::defaults();
    d.set_size(size);
    // SAFETY: the caller's struct has `size` writable bytes (its sizeof, documented), and
    // `size` is at most size_of::<T>(), so both ranges are in bounds.
    unsafe { std::ptr::copy_nonoverlapping((&d as *const T).cast::<u8>(), p.cast::<u8>(), size) };
    Ok(())
}

/// Reads the caller's struct: the fields its `size` covers, the defaults after them.
pub fn read<T: SizedParams>(p: *const T, what: &str) -> FfiResult<T> {
    if p.is_null() {
        return Err(FfiError::null(what));
    }
    // SAFETY: every SizedParams struct begins with its size_t size (asserted where each is
    // declared), and a non-NULL parameter pointer points to at least that.
    let size = unsafe { p.cast::<usize>().read() };
    check_size::<T>(size)?;
    let mut out = T::defaults();
    // SAFETY: `size` bytes are readable at `p` (the caller's sizeof) and fit in `out`.
    unsafe { std::ptr::copy_nonoverlapping(p.cast::<u8>(), (&mut out as *mut T).cast(), size) };
    out.set_size(std::mem::size_of::<T>());
    Ok(out)
}

/// Declares `$t` a [`SizedParams`] struct: its `size` field first, its last field `$last`
/// (of type `$last_ty`) ending the struct (no tail padding, so that a field appended later
/// never falls in an older caller's padding), and the size of its first versioned layout
/// (a literal: it never changes when fields are appended).
macro_rules! sized_params {
    ($t:ty, $name:literal, $last:ident: $last_ty:ty, $first_size:literal) => {
        const _: () = {
            assert!(std::mem::offset_of!($t, size) == 0);
            assert!(
                std::mem::offset_of!($t, $last) + std::mem::size_of::<$last_ty>()
                    == std::mem::size_of::<$t>(),
                "the struct ends in padding"
            );
            assert!($first_size <= std::mem::size_of::<$t>());
        };
        impl crate::sized::SizedParams for $t {
            const NAME: &'static str = $name;
            const FIRST_SIZE: usize = $first_size;
            fn defaults() -> Self {
                <$t>::defaults()
            }
            fn set_size(&mut self, size: usize) {
                self.size = size;
            }
        }
    };
}
pub(crate) use sized_params;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{FvRenderParams, FvUnstructuredVolumeDesc};

    /// `T` as a later minor version might declare it: one field appended.
    #[repr(C)]
    #[derive(Clone, Copy)]
    struct Later<T> {
        base: T,
        appended: f64,
    }
    impl<T: SizedParams> SizedParams for Later<T> {
        const NAME: &'static str = T::NAME;
        const FIRST_SIZE: usize = T::FIRST_SIZE;
        fn defaults() -> Self {
            Later {
                base: T::defaults(),
                appended: 42.0,
            }
        }
        fn set_size(&mut self, size: usize) {
            self.base.set_size(size);
        }
    }

    /// A `T` of this version, filled with its defaults and then `change`d, read by a later
    /// version: `check` holds of the fields it knew, and the appended one takes its default.
    fn older_reads_with_the_later_fields_at_their_defaults<T: SizedParams>(
        size_of: fn(&T) -> usize,
        change: fn(&mut T),
        check: fn(&T),
    ) {
        let mut older = std::mem::MaybeUninit::<T>::uninit();
        let size = std::mem::size_of::<T>();
        write_defaults(older.as_mut_ptr(), size, "params").unwrap();
        // SAFETY: write_defaults wrote all `size` bytes.
        let mut older = unsafe { older.assume_init() };
        assert_eq!(size_of(&older), size);
        change(&mut older);
        let read = read((&older as *const T).cast::<Later<T>>(), "params").unwrap();
        check(&read.base);
        assert_eq!(read.appended, 42.0, "the appended field takes its default");
        assert_eq!(size_of(&read.base), std::mem::size_of::<Later<T>>());
    }

    #[test]
    fn an_older_smaller_struct_reads_with_the_later_fields_at_their_defaults() {
        older_reads_with_the_later_fields_at_their_defaults::<FvRenderParams>(
            |p| p.size,
            |p| {
                p.sample_distance = 0.25;
                p.quadrature = 1;
            },
            |p| assert_eq!((p.sample_distance, p.quadrature), (0.25, 1)),
        );
        older_reads_with_the_later_fields_at_their_defaults::<FvUnstructuredVolumeDesc>(
            |d| d.size,
            |d| {
                d.cell_count = 7;
                d.location = 1;
            },
            |d| assert_eq!((d.cell_count, d.location, d.components), (7, 1, 1)),
        );
    }

    fn defaults_write_only_the_callers_size<T: SizedParams>() {
        let size = std::mem::size_of::<T>();
        let mut buf = vec![0xA5u8; std::mem::size_of::<Later<T>>()];
        write_defaults(buf.as_mut_ptr().cast::<Later<T>>(), size, "params").unwrap();
        assert!(
            buf[size..].iter().all(|&b| b == 0xA5),
            "nothing past the caller's size"
        );
    }

    #[test]
    fn defaults_write_only_what_the_callers_size_covers() {
        defaults_write_only_the_callers_size::<FvRenderParams>();
        defaults_write_only_the_callers_size::<FvUnstructuredVolumeDesc>();
    }

    #[test]
    fn sizes_outside_the_known_range_are_refused_with_a_message() {
        let mut p = FvRenderParams::defaults();
        for bad in [
            0,
            4,
            FvRenderParams::FIRST_SIZE - 8,
            std::mem::size_of::<FvRenderParams>() + 8,
        ] {
            p.size = bad;
            let e = read(&p, "params").unwrap_err();
            assert_eq!(e.status, crate::FvStatus::InvalidArgument);
            assert!(
                e.message.contains(&format!("FvRenderParams.size is {bad}")),
                "{}",
                e.message
            );
            let mut q = FvRenderParams::defaults();
            assert!(write_defaults(&mut q, bad, "params").is_err());
        }
    }
}
