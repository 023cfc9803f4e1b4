//! The export macro compiles in a crate that denies unsafe code, as the model crates do.
#![deny(unsafe_code)]

#[allow(unsafe_code)]
mod common;

fmi2_slave::export_fmi2!(common::Lag);

#[test]
fn the_macro_expands_under_deny_unsafe_code() {
    // Reaching this test means the 34 exports compiled under `#![deny(unsafe_code)]`.
    let _version: unsafe extern "C" fn() -> *const std::ffi::c_char = fmi2GetVersion;
    let _free: unsafe extern "C" fn(fmi2_slave::ffi::Fmi2Component) = fmi2FreeInstance;
    // and the model description the exports check at instantiation is valid
    assert_eq!(common::DESCRIPTION.validate(), Ok(()));
}
