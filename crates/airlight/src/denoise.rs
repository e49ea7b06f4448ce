//! Denoising with Intel Open Image Denoise (OIDN 2), its `RT` filter
//! guided by the first hits' albedo and normal. The library is loaded at
//! run time (`dlopen`), not linked: Debian has no package of it, and a
//! render without `--denoise` must not need it. The caller says where to
//! look ([`Denoiser::load`]); the command line and the Python package look
//! in `AIRLIGHT_OIDN`, next to a pip-installed `pyoidn` (whose wheel ships
//! the library with its CPU device), and on the system's library path.
//!
//! Once loaded the library stays loaded for the life of the process (its
//! thread pool does not survive being unloaded).

use crate::film::Image;
use std::ffi::{CStr, CString, c_char, c_void};
use std::path::PathBuf;

/// The library's file name on Linux.
pub const LIBRARY: &str = "libOpenImageDenoise.so.2";

type Handle = *mut c_void;

type NewDevice = unsafe extern "C" fn(i32) -> Handle;
type OnHandle = unsafe extern "C" fn(Handle);
type GetError = unsafe extern "C" fn(Handle, *mut *const c_char) -> i32;
type NewFilter = unsafe extern "C" fn(Handle, *const c_char) -> Handle;
type SetImage = unsafe extern "C" fn(Handle, *const c_char, *mut c_void, i32, usize, usize, usize, usize, usize);
type SetBool = unsafe extern "C" fn(Handle, *const c_char, bool);

/// The C functions used, looked up by name.
struct Api {
    new_device: NewDevice,
    commit_device: OnHandle,
    get_device_error: GetError,
    release_device: OnHandle,
    new_filter: NewFilter,
    set_shared_filter_image: SetImage,
    set_filter_bool: SetBool,
    commit_filter: OnHandle,
    execute_filter: OnHandle,
    release_filter: OnHandle,
}

/// OIDN's CPU device (`OIDN_DEVICE_TYPE_CPU`).
const DEVICE_CPU: i32 = 1;
/// Three 32-bit floats a pixel (`OIDN_FORMAT_FLOAT3`).
const FORMAT_FLOAT3: i32 = 3;

/// A loaded Open Image Denoise library.
pub struct Denoiser {
    api: Api,
    /// Where it was loaded from.
    pub path: PathBuf,
}

impl std::fmt::Debug for Denoiser {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Denoiser").field("path", &self.path).finish()
    }
}

impl Denoiser {
    /// Loads the library from the first of `candidates` that holds it (a
    /// file, or a folder holding [`LIBRARY`]; a bare name is searched on
    /// the system's library path); the error says where it looked.
    pub fn load(candidates: &[PathBuf]) -> Result<Denoiser, String> {
        let mut tried = Vec::new();
        for candidate in candidates {
            let path = if candidate.is_dir() { candidate.join(LIBRARY) } else { candidate.clone() };
            match open(&path) {
                Ok(api) => return Ok(Denoiser { api, path }),
                Err(why) => tried.push(format!("{}: {why}", path.display())),
            }
        }
        Err(format!(
            "Intel Open Image Denoise ({LIBRARY}) was not found; install it with `pip install pyoidn`, or set \
             AIRLIGHT_OIDN to the library or its folder. Looked at: {}",
            if tried.is_empty() { "nothing".into() } else { tried.join("; ") }
        ))
    }

    /// `colour` denoised by the `RT` filter for high dynamic range images,
    /// guided by the first hits' `albedo` and `normal` (both or neither,
    /// each the size of the image).
    pub fn denoise(&self, colour: &Image, guides: Option<(&Image, &Image)>) -> Result<Image, String> {
        let (w, h) = (colour.width as usize, colour.height as usize);
        if let Some((a, n)) = guides
            && (a.width, a.height, n.width, n.height) != (colour.width, colour.height, colour.width, colour.height)
        {
            return Err("the albedo and normal images must be the size of the image".into());
        }
        crate::memory::check("the denoised image", (w * h * 12 * 4) as u64).map_err(|e| e.to_string())?;
        let mut input: Vec<f32> = colour.pixels.iter().flat_map(|p| p.to_array()).collect();
        let mut albedo: Vec<f32> =
            guides.map_or(Vec::new(), |(a, _)| a.pixels.iter().flat_map(|p| p.to_array()).collect());
        let mut normal: Vec<f32> =
            guides.map_or(Vec::new(), |(_, n)| n.pixels.iter().flat_map(|p| p.to_array()).collect());
        let mut output = vec![0.0f32; w * h * 3];
        let api = &self.api;
        let name = |s: &str| CString::new(s).unwrap_or_default();
        // SAFETY: the functions are OIDN 2's, called as its C API says; the
        // buffers live until the filter has run and been released, and each
        // is w × h × 3 floats, as described to the filter.
        unsafe {
            let device = (api.new_device)(DEVICE_CPU);
            if device.is_null() {
                return Err("Open Image Denoise could not make a CPU device".into());
            }
            (api.commit_device)(device);
            let mut result = device_error(api, device);
            let filter = (api.new_filter)(device, name("RT").as_ptr());
            if result.is_ok() && !filter.is_null() {
                let image = |key: &str, data: &mut Vec<f32>| {
                    let ptr = data.as_mut_ptr() as *mut c_void;
                    (api.set_shared_filter_image)(filter, name(key).as_ptr(), ptr, FORMAT_FLOAT3, w, h, 0, 12, w * 12);
                };
                image("color", &mut input);
                if guides.is_some() {
                    image("albedo", &mut albedo);
                    image("normal", &mut normal);
                }
                image("output", &mut output);
                (api.set_filter_bool)(filter, name("hdr").as_ptr(), true);
                (api.commit_filter)(filter);
                (api.execute_filter)(filter);
                result = device_error(api, device);
                (api.release_filter)(filter);
            } else if result.is_ok() {
                result = Err("Open Image Denoise has no RT filter".into());
            }
            (api.release_device)(device);
            result?;
        }
        let pixels = output.chunks_exact(3).map(|c| crate::Rgb::new(c[0], c[1], c[2])).collect();
        Ok(Image { width: colour.width, height: colour.height, pixels })
    }
}

/// The device's pending error, if any.
///
/// # Safety
/// `device` is a live OIDN device of `api`.
unsafe fn device_error(api: &Api, device: Handle) -> Result<(), String> {
    let mut message: *const c_char = std::ptr::null();
    // SAFETY: as the caller promises; the message, when not null, is a C
    // string the library owns until its next call.
    let code = unsafe { (api.get_device_error)(device, &mut message) };
    if code == 0 {
        return Ok(());
    }
    let text = if message.is_null() {
        String::new()
    } else {
        // SAFETY: see above.
        unsafe { CStr::from_ptr(message) }.to_string_lossy().into_owned()
    };
    Err(format!("Open Image Denoise failed (error {code}): {text}"))
}

/// Opens the library at `path` and looks up every function.
fn open(path: &std::path::Path) -> Result<Api, String> {
    let file = CString::new(path.as_os_str().as_encoded_bytes()).map_err(|_| "a path with a NUL byte".to_string())?;
    // SAFETY: dlopen with a C string; the handle is kept for the life of
    // the process (see the module notes).
    let handle = unsafe { libc::dlopen(file.as_ptr(), libc::RTLD_NOW | libc::RTLD_LOCAL) };
    if handle.is_null() {
        // SAFETY: dlerror returns the last error as a C string or null.
        let why = unsafe { libc::dlerror() };
        let why = if why.is_null() {
            "cannot open".into()
        } else {
            unsafe { CStr::from_ptr(why) }.to_string_lossy().into_owned()
        };
        return Err(why);
    }
    let symbol = |name: &str| -> Result<*mut c_void, String> {
        let c = CString::new(name).unwrap_or_default();
        // SAFETY: a live handle and a C string.
        let f = unsafe { libc::dlsym(handle, c.as_ptr()) };
        if f.is_null() { Err(format!("it has no {name}")) } else { Ok(f) }
    };
    // SAFETY: each symbol is the OIDN 2 C function of that name, whose
    // signature the field's type states (OpenImageDenoise/oidn.h).
    unsafe {
        Ok(Api {
            new_device: std::mem::transmute::<*mut c_void, NewDevice>(symbol("oidnNewDevice")?),
            commit_device: std::mem::transmute::<*mut c_void, OnHandle>(symbol("oidnCommitDevice")?),
            get_device_error: std::mem::transmute::<*mut c_void, GetError>(symbol("oidnGetDeviceError")?),
            release_device: std::mem::transmute::<*mut c_void, OnHandle>(symbol("oidnReleaseDevice")?),
            new_filter: std::mem::transmute::<*mut c_void, NewFilter>(symbol("oidnNewFilter")?),
            set_shared_filter_image: std::mem::transmute::<*mut c_void, SetImage>(symbol("oidnSetSharedFilterImage")?),
            set_filter_bool: std::mem::transmute::<*mut c_void, SetBool>(symbol("oidnSetFilterBool")?),
            commit_filter: std::mem::transmute::<*mut c_void, OnHandle>(symbol("oidnCommitFilter")?),
            execute_filter: std::mem::transmute::<*mut c_void, OnHandle>(symbol("oidnExecuteFilter")?),
            release_filter: std::mem::transmute::<*mut c_void, OnHandle>(symbol("oidnReleaseFilter")?),
        })
    }
}
