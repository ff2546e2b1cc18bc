//! The header's thread notes, held against the Rust types behind the handles: what the
//! header lets several threads share must be `Sync`, what it lets move between threads must
//! be `Send`. (ffi/tests/c/thread_stress.c uses them that way from C.)

use ferrovol::{
    FvContext, FvFrame, FvRenderer, FvTransferFunction, FvUnstructuredVolume, FvVolume,
};

fn shared_by_threads<T: Send + Sync>() {}
fn used_by_one_thread_at_a_time<T: Send>() {}

#[test]
fn handle_types_allow_what_the_header_promises() {
    // "may be used from any thread; calls on one context may run concurrently"
    shared_by_threads::<FvContext>();
    // "immutable after creation; may be read from several threads at once"
    shared_by_threads::<FvVolume>();
    // "immutable; may be read from several threads at once"
    shared_by_threads::<FvUnstructuredVolume>();
    // "immutable; may be read from several threads at once"
    shared_by_threads::<FvFrame>();
    // "one thread at a time (it may move between threads)"
    used_by_one_thread_at_a_time::<FvRenderer>();
    used_by_one_thread_at_a_time::<FvTransferFunction>();
}
