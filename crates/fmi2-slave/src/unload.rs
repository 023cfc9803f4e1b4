//! What an FMU library holds between its load and its unload, and how it gives it back.
//!
//! A model's description and variable tables are built once, on first use, and kept for
//! every instance. Kept in `std::sync::LazyLock` statics they were never dropped: Rust does
//! not run destructors of statics, so each `dlopen`/`dlclose` cycle of a host lost them
//! (about 45 KB for TowingPlant, issue 15). [`LibraryLazy`] is the replacement: the same
//! lazily built, shared value, allocated on the heap and recorded here, and dropped by the
//! library's destructor ([`on_unload`], in `.fini_array`, placed by
//! [`export_fmi2!`](crate::export_fmi2)) when the library is unloaded.
//!
//! The destructor frees the values only when that is sound, i.e. when no code can use them
//! any more:
//!
//! * **`dlclose`** of the last handle: the library's code is unmapped right after its
//!   destructor, so nothing of the library runs again. Values are freed unless an instance
//!   is still alive (a host that unloads without `fmi2FreeInstance` leaks those instances;
//!   the tables stay with them).
//! * **process exit** (`exit`, or `main` returning), the library still loaded or the code
//!   linked into an executable: other threads may still run and hold references, so
//!   nothing is freed (the process ends anyway). Exit is told from unload by a handler
//!   registered with `__cxa_atexit` for this library ([`on_load`], in `.init_array`): `exit`
//!   runs such handlers before any `.fini_array`, `dlclose` runs the library's own
//!   `.fini_array` first. Where the handler cannot be registered (another C library than
//!   glibc, another OS), nothing is ever freed: the former behaviour.

use std::fmt;
use std::ops::Deref;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::ptr::NonNull;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Mutex, OnceLock};

/// A value built on first use and shared until the library is unloaded: `LazyLock` for an
/// FMU library's statics (model description, variable tables), whose value is dropped when
/// the host unloads the library (see the [module documentation](self)).
///
/// ```
/// use fmi2_slave::LibraryLazy;
/// static SQUARES: LibraryLazy<Vec<u64>> = LibraryLazy::new(|| (0..8).map(|i| i * i).collect());
/// assert_eq!(SQUARES[3], 9);
/// ```
pub struct LibraryLazy<T: Send + Sync + 'static> {
    value: OnceLock<Shared<T>>,
    init: fn() -> T,
}

/// The heap value of a [`LibraryLazy`]; owned by [`HELD`], which frees it on unload.
struct Shared<T>(NonNull<T>);

// SAFETY: a shared reference to a `T: Sync` value, handed to any thread.
unsafe impl<T: Send + Sync> Send for Shared<T> {}
// SAFETY: as above.
unsafe impl<T: Send + Sync> Sync for Shared<T> {}

impl<T: Send + Sync + 'static> LibraryLazy<T> {
    /// A value that `init` builds on first access.
    pub const fn new(init: fn() -> T) -> Self {
        LibraryLazy {
            value: OnceLock::new(),
            init,
        }
    }

    /// The value, built now if this is the first access.
    pub fn force(this: &Self) -> &T {
        let shared = this.value.get_or_init(|| {
            let ptr = NonNull::from(Box::leak(Box::new((this.init)())));
            hold(ptr.as_ptr().cast(), drop_box::<T>);
            Shared(ptr)
        });
        // SAFETY: the box lives until `on_unload` frees it, which happens only when the
        // library is unloaded and no code of it runs any more (module documentation).
        unsafe { shared.0.as_ref() }
    }
}

impl<T: Send + Sync + 'static> Deref for LibraryLazy<T> {
    type Target = T;

    fn deref(&self) -> &T {
        LibraryLazy::force(self)
    }
}

impl<T: Send + Sync + fmt::Debug + 'static> fmt::Debug for LibraryLazy<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.value.get() {
            // SAFETY: as in `force`.
            Some(shared) => f
                .debug_tuple("LibraryLazy")
                .field(unsafe { shared.0.as_ref() })
                .finish(),
            None => f.write_str("LibraryLazy(<not built>)"),
        }
    }
}

/// One value to free on unload: its box and the function that drops it.
struct Held {
    ptr: *mut (),
    free: unsafe fn(*mut ()),
}

// SAFETY: the pointer is only dereferenced by `on_unload` (its `T` is `Send`).
unsafe impl Send for Held {}

/// Every value built so far, in construction order.
static HELD: Mutex<Vec<Held>> = Mutex::new(Vec::new());
/// Instances alive (`fmi2Instantiate` begun, `fmi2FreeInstance` not yet finished).
static LIVE_INSTANCES: AtomicUsize = AtomicUsize::new(0);
/// Whether the exit handler is registered, so that [`EXITING`] can be trusted.
static EXIT_HOOK: AtomicBool = AtomicBool::new(false);
/// Set by the exit handler: the process is exiting, not unloading the library.
static EXITING: AtomicBool = AtomicBool::new(false);

fn hold(ptr: *mut (), free: unsafe fn(*mut ())) {
    HELD.lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
        .push(Held { ptr, free });
}

/// # Safety
/// `p` came from `Box::<T>::into_raw` (or `leak`) and is used by nothing else.
unsafe fn drop_box<T>(p: *mut ()) {
    // SAFETY: the caller's contract.
    drop(unsafe { Box::from_raw(p.cast::<T>()) });
}

/// An instance is being created (call before anything touches a [`LibraryLazy`]).
pub(crate) fn instance_begun() {
    LIVE_INSTANCES.fetch_add(1, Ordering::SeqCst);
}

/// An instance was freed, or its creation failed.
pub(crate) fn instance_ended() {
    LIVE_INSTANCES.fetch_sub(1, Ordering::SeqCst);
}

#[cfg(all(target_os = "linux", target_env = "gnu"))]
mod exit_hook {
    use std::ffi::{c_int, c_void};

    extern "C" {
        /// This library's handle (crtbeginS.o): handlers registered with it run at `exit`
        /// and when the library is unloaded, and are forgotten then.
        static __dso_handle: u8;
        fn __cxa_atexit(
            f: unsafe extern "C" fn(*mut c_void),
            arg: *mut c_void,
            dso: *const c_void,
        ) -> c_int;
    }

    unsafe extern "C" fn mark_exiting(_: *mut c_void) {
        super::EXITING.store(true, std::sync::atomic::Ordering::SeqCst);
    }

    /// Registers [`mark_exiting`]; whether that worked.
    pub(super) fn register() -> bool {
        // SAFETY: `__cxa_atexit` with a handler of this library and this library's handle,
        // as the C++ runtime does for static destructors; glibc calls the handler at `exit`
        // or drops it when the library is unloaded.
        unsafe {
            __cxa_atexit(
                mark_exiting,
                std::ptr::null_mut(),
                std::ptr::addr_of!(__dso_handle).cast(),
            ) == 0
        }
    }
}

#[cfg(not(all(target_os = "linux", target_env = "gnu")))]
mod exit_hook {
    /// Exit cannot be told from unload here: nothing is ever freed.
    pub(super) fn register() -> bool {
        false
    }
}

/// The library's constructor (`.init_array`, placed by `export_fmi2!`): registers the exit
/// handler that tells process exit from unloading.
pub extern "C" fn on_load() {
    if exit_hook::register() {
        EXIT_HOOK.store(true, Ordering::SeqCst);
    }
}

/// The library's destructor (`.fini_array`, placed by `export_fmi2!`): frees every
/// [`LibraryLazy`] value, newest first, when the library is being unloaded with no instance
/// alive; does nothing at process exit (module documentation). Never unwinds.
pub extern "C" fn on_unload() {
    let unloading = EXIT_HOOK.load(Ordering::SeqCst) && !EXITING.load(Ordering::SeqCst);
    if !unloading || LIVE_INSTANCES.load(Ordering::SeqCst) != 0 {
        return;
    }
    let held = std::mem::take(
        &mut *HELD
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner),
    );
    for Held { ptr, free } in held.into_iter().rev() {
        // SAFETY: `ptr` is a box `force` leaked and recorded once; nothing uses it any more.
        if let Err(payload) = catch_unwind(AssertUnwindSafe(|| unsafe { free(ptr) })) {
            std::mem::forget(payload);
        }
    }
}
