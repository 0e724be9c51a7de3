//! The C step on an NVIDIA GPU: the kernel (`kernel/*.h` and
//! `kernel/kernel.cu`) compiled at run time by NVRTC to a CUBIN for the
//! device's own architecture (never PTX, which a driver older than NVRTC
//! refuses), with `--fmad=false` so that the GPU gives the CPU's bits, and
//! launched with one thread per creature. The driver and NVRTC are loaded
//! when a [`Device`] is opened; where either is missing, opening says which.
//!
//! Run on a lent NVIDIA H200: the same bits as the CPU (docs/GPU.md).
//! `bench/gpu.sh` checks it there.

use crate::pack::{Array, Batch, Raw, Slice};
use crate::Mode;
use cudarc::driver::{
    CudaContext, CudaFunction, CudaSlice, CudaStream, DevicePtr, DeviceRepr, LaunchConfig,
    PushKernelArg,
};
use std::sync::Arc;

/// The kernel's source: the headers in include order, then the entry.
fn source() -> String {
    let strip = |text: &str| {
        text.lines()
            .filter(|l| !l.trim_start().starts_with("#include"))
            .collect::<Vec<_>>()
            .join("\n")
    };
    [
        include_str!("../kernel/libm.h"),
        include_str!("../kernel/terrain.h"),
        include_str!("../kernel/spheres.h"),
        include_str!("../kernel/trig.h"),
        include_str!("../kernel/exp.h"),
        include_str!("../kernel/step.h"),
        include_str!("../kernel/eval.h"),
        include_str!("../kernel/kernel.cu"),
    ]
    .iter()
    .map(|t| strip(t))
    .collect::<Vec<_>>()
    .join("\n")
}

/// A GPU ready to step batches.
pub struct Device {
    ctx: Arc<CudaContext>,
    stream: Arc<CudaStream>,
    /// The whole kernel for batches on the flat floor (or none), compiled
    /// with `AN_FLAT_ONLY` when the device is opened (so that a kernel
    /// NVRTC refuses is reported then): without terrain's code it holds
    /// fewer registers.
    flat: Arc<Kernels>,
    /// Every other kernel a batch has needed, compiled when the first such
    /// batch came (or the error its compilation gave), by what it was
    /// compiled for.
    kept: std::sync::Mutex<Vec<(KernelKey, Compiled)>>,
    /// Whether each batch runs a kernel specialised for it ([`Special`];
    /// `ANIMATS_GPU_SPECIALISE`, on unless `0`), or the whole one of its
    /// floor.
    specialise: bool,
    name: String,
    arch: (i32, i32),
    mode: Mode,
    schedule: Schedule,
    tuning: Tuning,
    /// Whether [`Device::into_batches`] packs each batch in order of size
    /// (`ANIMATS_GPU_SORT`, [`crate::order`]).
    sort: bool,
    /// The layout [`Device::into_batches`] fixes (`ANIMATS_GPU_LAYOUT`);
    /// `None`: learned ([`crate::layout_choice`]).
    layout: Option<crate::Layout>,
}

/// Two knobs for measuring on a GPU, read by [`Device::open`] from the
/// environment: `ANIMATS_GPU_REGS` (16 to 255: NVRTC's `--maxrregcount`,
/// the registers a thread may hold, the rest spilled to local memory; part
/// of a kept kernel's name) and `ANIMATS_GPU_BLOCK` (32 to 1024, a
/// multiple of 32: threads a block; unless set, 128 (`BLOCK`), or fewer where
/// that puts fewer warps on the busiest multiprocessor: see
/// [`threads_a_block`]). Neither
/// changes a bit of a result: they decide where values are kept and which
/// threads run together, not the arithmetic. A block whose threads need
/// more registers than a multiprocessor has (1,024 threads at 255) is
/// refused by the launch, with the driver's error.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Tuning {
    /// `--maxrregcount`, if set.
    pub regs: Option<u32>,
    /// Threads a block, if set; `None`: [`threads_a_block`] chooses.
    pub block: Option<u32>,
}

impl Tuning {
    /// The knobs from `ANIMATS_GPU_REGS` and `ANIMATS_GPU_BLOCK`; `Err`
    /// names the variable and the value it refuses.
    pub fn from_env() -> Result<Tuning, String> {
        let get = |name| std::env::var(name).ok();
        Tuning::parse(
            get("ANIMATS_GPU_REGS").as_deref(),
            get("ANIMATS_GPU_BLOCK").as_deref(),
        )
    }

    /// The knobs from the variables' values (`None`: unset).
    pub fn parse(regs: Option<&str>, block: Option<&str>) -> Result<Tuning, String> {
        let number = |name: &str, v: &str, ok: &dyn Fn(u32) -> bool, what: &str| {
            v.trim()
                .parse::<u32>()
                .ok()
                .filter(|&n| ok(n))
                .ok_or_else(|| format!("{name}: {what}, got {v:?}"))
        };
        let regs = regs
            .map(|v| {
                number(
                    "ANIMATS_GPU_REGS",
                    v,
                    &|n| (16..=255).contains(&n),
                    "a whole number from 16 to 255",
                )
            })
            .transpose()?;
        let block = block
            .map(|v| {
                number(
                    "ANIMATS_GPU_BLOCK",
                    v,
                    &|n| (32..=1024).contains(&n) && n % 32 == 0,
                    "a multiple of 32 from 32 to 1024",
                )
            })
            .transpose()?;
        Ok(Tuning { regs, block })
    }
}

/// A kernel compiled, or the error its compilation gave.
type Compiled = Result<Arc<Kernels>, String>;

/// One compiled kernel's entries.
struct Kernels {
    step: CudaFunction,
    evaluate: CudaFunction,
    /// Evaluation threads the GPU holds at once (its multiprocessors
    /// times the blocks of the evaluation each holds, times the block's threads):
    /// the threads of a [`Schedule::Queue`] launch.
    resident: i64,
    /// The GPU's multiprocessors.
    sms: i64,
}

/// How a GPU's threads share the evaluations of a batch. Either gives the
/// same bits (each evaluation is computed whole by one thread, whichever).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Schedule {
    /// One thread per evaluation, in batch order. A warp's 32 threads run
    /// until its longest evaluation ends (an end rule stops others early).
    #[default]
    Static,
    /// As many threads as the GPU holds at once, each taking the next
    /// evaluation from a shared counter when its last one ends, so that a
    /// warp's threads keep evaluating while any evaluation is left.
    Queue,
}

impl std::fmt::Debug for Device {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{} (sm_{}{})", self.name, self.arch.0, self.arch.1)
    }
}

impl Device {
    /// The first GPU, with the kernel compiled for it in strict mode (the
    /// engine's bits); `Err` names what is missing: the driver, a device,
    /// NVRTC, or the compilation's log.
    pub fn open() -> Result<Device, String> {
        Device::open_in(Mode::Strict)
    }

    /// [`Device::open`], the kernel compiled in `mode`.
    pub fn open_in(mode: Mode) -> Result<Device, String> {
        // SAFETY: only looks for the library (dlopen), calls nothing in it.
        if !unsafe { cudarc::driver::sys::is_culib_present() } {
            return Err(
                "no NVIDIA driver: libcuda.so cannot be loaded (a GPU machine with the NVIDIA driver installed is needed)"
                    .into(),
            );
        }
        let ctx = CudaContext::new(0).map_err(|e| format!("no CUDA device: {e}"))?;
        // SAFETY: as above.
        if !unsafe { cudarc::nvrtc::sys::is_culib_present() } {
            return Err(
                "NVRTC cannot be loaded (libnvrtc.so): install CUDA's NVRTC, e.g. the PyPI package nvidia-cuda-nvrtc, and put the folder holding libnvrtc.so and libnvrtc-builtins.so on LD_LIBRARY_PATH"
                    .into(),
            );
        }
        let arch = ctx
            .compute_capability()
            .map_err(|e| format!("the device's architecture: {e}"))?;
        let name = ctx.name().unwrap_or_else(|_| "an NVIDIA GPU".into());
        let tuning = Tuning::from_env()?;
        let sort = crate::order::sort_from_env()?;
        let layout = crate::layout_choice::layout_from_env()?;
        let specialise = specialise_from_env()?;
        let flat = Arc::new(kernels(
            &ctx,
            arch,
            &name,
            KernelKey::WHOLE_FLAT,
            mode,
            tuning,
        )?);
        Ok(Device {
            stream: ctx.default_stream(),
            ctx,
            flat,
            kept: Default::default(),
            specialise,
            name,
            arch,
            mode,
            schedule: Schedule::default(),
            tuning,
            sort,
            layout,
        })
    }

    /// The kernel for `batch`: the flat floor's, terrain's or sphere
    /// contact's, with implicit Euler if the batch steps with it, and
    /// specialised for the batch ([`Special`]) if it holds at least
    /// [`SPECIALISE_FROM`] creatures, unless `ANIMATS_GPU_SPECIALISE=0`;
    /// compiled now if no batch needed it yet (or read from the disk's
    /// cache).
    fn kernels(&self, batch: &Batch) -> Result<Arc<Kernels>, String> {
        self.kernels_for(KernelKey::of(batch, self.specialise))
            .map(|(k, _)| k)
    }

    /// The kernel `key` names, and whether it was made now (compiled, or
    /// read from the disk's cache) rather than found made.
    fn kernels_for(&self, key: KernelKey) -> Result<(Arc<Kernels>, bool), String> {
        if key == KernelKey::WHOLE_FLAT {
            return Ok((self.flat.clone(), false));
        }
        let mut kept = self
            .kept
            .lock()
            .map_err(|_| "the GPU's kernels: a thread panicked while compiling one".to_string())?;
        if let Some((_, k)) = kept.iter().find(|(k, _)| *k == key) {
            return k.clone().map(|k| (k, false));
        }
        let compiled = kernels(
            &self.ctx,
            self.arch,
            &self.name,
            key,
            self.mode,
            self.tuning,
        )
        .map(Arc::new);
        kept.push((key, compiled.clone()));
        compiled.map(|k| (k, true))
    }

    /// What the driver says of the kernel for `batch` (compiled now if it
    /// was not): each entry's registers a thread, local memory a thread,
    /// and the warps a multiprocessor holds in the blocks `batch` is
    /// launched in — the figures docs/GPU.md's table of specialised
    /// kernels computes from ptxas's report.
    pub fn kernel_report(&self, batch: &Batch) -> Result<String, String> {
        let kernels = self.kernels(batch)?;
        let n = i64::try_from(batch.creatures()).unwrap_or(i64::MAX);
        let block = threads_a_block(n, kernels.sms, self.tuning.block);
        let entry = |name: &str, f: &CudaFunction| -> Result<String, String> {
            let e = |e: cudarc::driver::DriverError| format!("the {name}'s attributes: {e}");
            let blocks = f
                .occupancy_max_active_blocks_per_multiprocessor(block, 0, None)
                .map_err(e)?;
            Ok(format!(
                "{name} {} registers, {} bytes local, {} warps a multiprocessor",
                f.num_regs().map_err(e)?,
                f.local_size_bytes().map_err(e)?,
                i64::from(blocks) * i64::from(block) / 32
            ))
        };
        Ok(format!(
            "{}; {} (blocks of {block})",
            entry("evaluation", &kernels.evaluate)?,
            entry("step", &kernels.step)?
        ))
    }

    /// The options the kernel for `batch` is compiled with beyond the
    /// mode's own ([`kernel_options`], as this device specialises).
    pub fn kernel_options(&self, batch: &Batch) -> Vec<String> {
        kernel_options(batch, self.specialise)
    }

    /// The mode its kernels were compiled in.
    pub fn mode(&self) -> Mode {
        self.mode
    }

    /// The device's name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The knobs it was opened with ([`Tuning`]).
    pub fn tuning(&self) -> Tuning {
        self.tuning
    }

    /// Threads a block in a launch of one thread per creature of
    /// `creatures` ([`threads_a_block`] on this GPU, with its knob).
    pub fn threads_a_block(&self, creatures: usize) -> u32 {
        let n = i64::try_from(creatures).unwrap_or(i64::MAX);
        threads_a_block(n, self.flat.sms, self.tuning.block)
    }

    /// How [`Device::evaluate`] shares a batch's evaluations among the
    /// GPU's threads ([`Schedule::Static`] unless set).
    pub fn set_schedule(&mut self, schedule: Schedule) {
        self.schedule = schedule;
    }

    /// Compiles (or reads from the disk's cache) the kernel for `batch`,
    /// loads it and launches its evaluation on none of the batch's
    /// creatures, so that a run timed after it holds the evaluation alone.
    /// Changes nothing of the batch.
    pub fn prepare(&self, batch: &Batch) -> Result<(), String> {
        let s = &self.stream;
        let (_on_device, raw) = upload(s, batch)?;
        let kernels = self.kernels(batch)?;
        let (none, local, queue) = (0i64, batch.layout().flag(), 0i32);
        let next = s
            .alloc_zeros::<u64>(1)
            .map_err(err("the queue's counter"))?;
        let mut launch = s.launch_builder(&kernels.evaluate);
        launch
            .arg(&raw)
            .arg(&none)
            .arg(&local)
            .arg(&next)
            .arg(&queue);
        // SAFETY: as in `evaluate`; with no creatures the one thread
        // returns before reading anything.
        unsafe { launch.launch(config(1, 32)?) }.map_err(err("launching the evaluation"))?;
        s.synchronize().map_err(err("waiting for the GPU"))
    }

    /// Steps every creature of `batch` `steps` times on the GPU (one
    /// thread each) and copies the positions and velocities back.
    pub fn run(&self, batch: &mut Batch, steps: u64) -> Result<(), String> {
        let s = &self.stream;
        let (on_device, raw) = upload(s, batch)?;
        let creatures = batch.creatures() as i64;
        let steps = steps.min(i64::MAX as u64) as i64;
        let local = batch.layout().flag();
        let kernels = self.kernels(batch)?;
        let mut launch = s.launch_builder(&kernels.step);
        launch.arg(&raw).arg(&creatures).arg(&steps).arg(&local);
        // SAFETY: the kernel reads and writes within the arrays just
        // uploaded, at the offsets `Batch::pack` checked; the arguments
        // match its signature (an_batch by value, two long longs, an int).
        let block = threads_a_block(creatures, kernels.sms, self.tuning.block);
        unsafe { launch.launch(config(creatures, block)?) }.map_err(err("launching the step"))?;
        let pos = download_f64(s, &on_device, Array::Pos)?;
        let vel = download_f64(s, &on_device, Array::Vel)?;
        let failed = download_i64(s, &on_device, Array::Failed)?;
        let clock = download_f64(s, &on_device, Array::Clock)?;
        batch.set_state(&pos, &vel, &failed, &clock);
        batch.ran(steps as u64);
        Ok(())
    }

    /// Runs every scene's evaluation of a batch of scenes
    /// ([`Batch::pack_scenes`]) on the GPU, one thread per scene: the
    /// evaluations [`Batch::evaluate_cpu`] gives, to the bit. The batch's
    /// states become the scenes' last ones.
    pub fn evaluate(
        &self,
        batch: &mut Batch,
    ) -> Result<Vec<animats_scene::evaluate::Evaluation>, String> {
        batch.take_ready()?;
        let s = &self.stream;
        let (on_device, raw) = upload(s, batch)?;
        let creatures = batch.creatures() as i64;
        let local = batch.layout().flag();
        // The shared counter of the queue (zero: the first evaluation).
        let next = s
            .alloc_zeros::<u64>(1)
            .map_err(err("the queue's counter"))?;
        let kernels = self.kernels(batch)?;
        let (queue, threads) = match self.schedule {
            Schedule::Static => (0i32, creatures),
            Schedule::Queue => (1i32, creatures.min(kernels.resident)),
        };
        let mut launch = s.launch_builder(&kernels.evaluate);
        launch
            .arg(&raw)
            .arg(&creatures)
            .arg(&local)
            .arg(&next)
            .arg(&queue);
        // SAFETY: as in `run`; the kernel takes an_batch by value, one
        // long long, an int, the counter's device pointer and an int; with
        // the queue, threads take evaluations below `creatures` only.
        let block = threads_a_block(threads, kernels.sms, self.tuning.block);
        unsafe { launch.launch(config(threads, block)?) }
            .map_err(err("launching the evaluation"))?;
        let pos = download_f64(s, &on_device, Array::Pos)?;
        let vel = download_f64(s, &on_device, Array::Vel)?;
        let failed = download_i64(s, &on_device, Array::Failed)?;
        let clock = download_f64(s, &on_device, Array::Clock)?;
        batch.set_state(&pos, &vel, &failed, &clock);
        let result = download_f64(s, &on_device, Array::Result)?;
        let ended = download_i64(s, &on_device, Array::Ended)?;
        let measures = download_f64(s, &on_device, Array::MeasureSum)?;
        batch.set_results(&result, &ended, &measures);
        Ok(batch.evaluations())
    }
}

impl Device {
    /// The device as a problem's evaluation runner
    /// ([`animats_scene::evaluate::Batches`]): each batch of scenes packed
    /// ([`Batch::pack_scenes`]) and evaluated here, one batch at a time;
    /// in order of size where `ANIMATS_GPU_SORT=1` ([`crate::order`]), the evaluations handed
    /// back in the scenes' own order either way; each layout tried on one
    /// batch and the faster kept ([`crate::layout_choice`]) unless
    /// `ANIMATS_GPU_LAYOUT` fixes one.
    pub fn into_batches(self) -> animats_scene::evaluate::Batches {
        self.into_batches_with(|_| ())
    }

    /// [`Device::into_batches`], the line saying which layout was chosen,
    /// and why, given to `say` once.
    pub fn into_batches_with(
        self,
        say: impl Fn(String) + Send + Sync + 'static,
    ) -> animats_scene::evaluate::Batches {
        let sort = self.sort;
        let choice = crate::layout_choice::LayoutChoice::new(self.layout);
        let runner = std::sync::Mutex::new((self, choice));
        animats_scene::evaluate::Batches(Arc::new(move |scenes| {
            let refs: Vec<&animats_scene::Scene> = scenes.iter().collect();
            crate::order::evaluate_in_order(&refs, sort, |refs| {
                let mut batch = Batch::pack_scenes(refs)?;
                let mut runner = runner
                    .lock()
                    .map_err(|_| "an earlier evaluation on the GPU panicked".to_string())?;
                let (device, choice) = &mut *runner;
                let layout = choice.next();
                batch.set_layout(layout);
                // The kernel compiled first (a batch's first needs it), so
                // that the clock times the evaluation alone; a compilation
                // (NVRTC: seconds) said, so that a pause is not taken for a hang.
                let key = KernelKey::of(&batch, device.specialise);
                let t = std::time::Instant::now();
                let (_, made) = device.kernels_for(key)?;
                let took = t.elapsed().as_secs_f64();
                if made && took >= 1.0 {
                    say(format!(
                        "GPU: the kernel for this run's batches ({}) compiled in {took:.1} s; kept on disk for later runs",
                        key.options().join(" ")
                    ));
                }
                let t = std::time::Instant::now();
                let evaluations = device.evaluate(&mut batch)?;
                let simulated: f64 = evaluations.iter().map(|e| e.time).sum();
                if let Some(line) = choice.record(layout, t.elapsed().as_secs_f64(), simulated) {
                    say(line);
                }
                Ok(evaluations)
            })
        }))
    }
}

/// Which of the kernels: each holds only the code its batches need, so
/// that the commonest hold the fewest registers (each also with implicit
/// Euler, `AN_WITH_IMPLICIT`, for batches that step with it).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Variant {
    /// The flat floor (or none): `AN_FLAT_ONLY`.
    Flat = 0,
    /// Terrain.
    Terrain = 1,
    /// Sphere contact on the flat floor: `AN_FLAT_ONLY` and `AN_SPHERES`.
    Spheres = 2,
}

/// Creatures a batch holds from which it runs a kernel specialised for it
/// ([`Special`]): NVRTC takes about 10 s to compile one on an H200's host
/// and 40 s on a 2-core Xeon (once a machine: it is kept on disk), more
/// than a smaller batch's whole run on the GPU could gain (4,096 roobots took 0.08 s on an H200,
/// 2026-11-30), so smaller batches run the whole kernel of their floor,
/// compiled when the device is opened.
pub const SPECIALISE_FROM: usize = 4096;

/// A kernel specialised for a batch: its integrator as a constant and
/// without the parts none of its creatures has (`kernel/step.h`,
/// `AN_ONLY_INTEGRATOR` and `AN_ABSENT`). The compiler drops their code, so
/// the kernel holds fewer registers and more warps fit on a
/// multiprocessor (`bench/nvrtc.py sm_90 -- OPTIONS`: a batch of walkers'
/// evaluation 222 registers → 136; docs/GPU.md); the same bits, as only
/// code that would have run zero times for the batch is left out (the C
/// skips the same code at run time, `Batch::absent`, in every parity
/// test). Batches of one scene share one: a run compiles one or two.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Special {
    /// The C's number of the batch's integrator.
    pub integrator: i32,
    /// `AN_ABSENT`: the parts no creature of the batch has.
    pub absent: u32,
}

impl Special {
    /// `batch`'s.
    pub fn of(batch: &Batch) -> Special {
        Special {
            integrator: batch.integrator_code(),
            absent: batch.absent(),
        }
    }
}

/// What a kernel is compiled for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct KernelKey {
    variant: Variant,
    implicit: bool,
    special: Option<Special>,
}

impl KernelKey {
    /// The flat floor's whole kernel, compiled when a device is opened.
    const WHOLE_FLAT: KernelKey = KernelKey {
        variant: Variant::Flat,
        implicit: false,
        special: None,
    };

    /// The kernel `batch` needs: specialised for it if `specialise`.
    fn of(batch: &Batch, specialise: bool) -> KernelKey {
        let variant = if batch.sphere_contact() {
            Variant::Spheres
        } else if batch.on_terrain() {
            Variant::Terrain
        } else {
            Variant::Flat
        };
        KernelKey {
            variant,
            implicit: batch.implicit(),
            special: (specialise && batch.creatures() >= SPECIALISE_FROM)
                .then(|| Special::of(batch)),
        }
    }

    /// Its options beyond the mode's and the tuning's.
    fn options(self) -> Vec<String> {
        let mut options = Vec::new();
        if self.variant != Variant::Terrain {
            options.push("-DAN_FLAT_ONLY".into());
        }
        if self.variant == Variant::Spheres {
            options.push("-DAN_SPHERES".into());
        }
        if self.implicit {
            options.push("-DAN_WITH_IMPLICIT".into());
        }
        if let Some(s) = self.special {
            options.push(format!("-DAN_ONLY_INTEGRATOR={}", s.integrator));
            options.push(format!("-DAN_ABSENT={}", s.absent));
        }
        options
    }
}

/// The options the kernel for `batch` is compiled with beyond the mode's
/// own and the tuning's: which floor, implicit Euler, and where
/// `specialise` (and the batch holds at least [`SPECIALISE_FROM`]
/// creatures), the batch's specialisation (`-DAN_ONLY_INTEGRATOR=…
/// -DAN_ABSENT=…`, [`Special`]). Needs no GPU: `bench/nvrtc.py` compiles
/// a kernel with them.
pub fn kernel_options(batch: &Batch, specialise: bool) -> Vec<String> {
    KernelKey::of(batch, specialise).options()
}

/// `ANIMATS_GPU_SPECIALISE`: unset, empty or `1` gives each batch a kernel
/// specialised for it ([`Special`]); `0` the whole kernel of its floor;
/// anything else is refused by name.
pub fn specialise_from_env() -> Result<bool, String> {
    parse_specialise(std::env::var("ANIMATS_GPU_SPECIALISE").ok().as_deref())
}

/// [`specialise_from_env`] from the variable's value (`None`: unset).
pub fn parse_specialise(v: Option<&str>) -> Result<bool, String> {
    match v.map(str::trim) {
        None | Some("") | Some("1") => Ok(true),
        Some("0") => Ok(false),
        Some(other) => Err(format!(
            "ANIMATS_GPU_SPECIALISE: 1 (a kernel specialised for each batch) or 0 (the whole kernel), got {other:?}"
        )),
    }
}

/// The kernel `key` compiled for `arch` in `mode`, from the disk's
/// cache where an earlier run kept it (src/cache.rs), else by NVRTC now,
/// and kept.
fn kernels(
    ctx: &Arc<CudaContext>,
    arch: (i32, i32),
    name: &str,
    key: KernelKey,
    mode: Mode,
    tuning: Tuning,
) -> Result<Kernels, String> {
    let src = source();
    let mut options = options(arch, mode);
    if let Some(n) = tuning.regs {
        options.push(format!("--maxrregcount={n}"));
    }
    options.extend(key.options());
    let kept = crate::cache::folder()
        .map(|dir| crate::cache::file(&dir, &[&src, &options.join(" "), &nvrtc_version()], arch));
    let load = |cubin: Vec<u8>| ctx.load_module(cudarc::nvrtc::Ptx::from_binary(cubin));
    let cached = kept
        .as_deref()
        .and_then(crate::cache::read)
        .and_then(|cubin| load(cubin).ok());
    let module = match cached {
        Some(module) => module,
        None => {
            let cubin = compile(&src, &options, arch)?;
            let module = load(cubin.clone())
                .map_err(|e| format!("loading the compiled step on {name}: {e}"))?;
            if let Some(path) = &kept {
                // Without a cache the next run compiles again: no error.
                let _ = crate::cache::write(path, &cubin);
            }
            module
        }
    };
    let step = module
        .load_function("animats_step_kernel")
        .map_err(|e| format!("the step's entry: {e}"))?;
    let evaluate = module
        .load_function("animats_evaluate_kernel")
        .map_err(|e| format!("the evaluation's entry: {e}"))?;
    let sms = ctx
        .attribute(
            cudarc::driver::sys::CUdevice_attribute::CU_DEVICE_ATTRIBUTE_MULTIPROCESSOR_COUNT,
        )
        .map_or(1, |n| i64::from(n.max(1)));
    let block = tuning.block.unwrap_or(BLOCK);
    let per_sm = evaluate
        .occupancy_max_active_blocks_per_multiprocessor(block, 0, None)
        .map_err(|e| format!("the evaluation's occupancy: {e}"))?
        .max(1);
    Ok(Kernels {
        step,
        evaluate,
        resident: sms * i64::from(per_sm) * i64::from(block),
        sms,
    })
}

/// A driver error as a message saying what was being done.
fn err(what: &'static str) -> impl Fn(cudarc::driver::DriverError) -> String {
    move |e| format!("{what}: {e}")
}

/// Every array of `batch` copied to the device (an empty one as one
/// element: no zero-size allocation), and the kernel's struct pointing at
/// the copies.
fn upload(s: &Arc<CudaStream>, batch: &Batch) -> Result<(Vec<OnDevice>, DeviceBatch), String> {
    let mut on_device = Vec::with_capacity(Array::ALL.len());
    for a in Array::ALL {
        let up = match batch.array(a) {
            Slice::F64(v) => OnDevice::F64(
                s.clone_htod(if v.is_empty() { &[0.0][..] } else { v })
                    .map_err(err("copying to the GPU"))?,
            ),
            Slice::I32(v) => OnDevice::I32(
                s.clone_htod(if v.is_empty() { &[0][..] } else { v })
                    .map_err(err("copying to the GPU"))?,
            ),
            Slice::I64(v) => OnDevice::I64(
                s.clone_htod(if v.is_empty() { &[0][..] } else { v })
                    .map_err(err("copying to the GPU"))?,
            ),
        };
        on_device.push(up);
    }
    let addresses: Vec<u64> = on_device
        .iter()
        .map(|d| match d {
            OnDevice::F64(x) => x.device_ptr(s).0,
            OnDevice::I32(x) => x.device_ptr(s).0,
            OnDevice::I64(x) => x.device_ptr(s).0,
        })
        .collect();
    let raw = DeviceBatch(batch.raw_with(|a| addresses[a as usize]));
    Ok((on_device, raw))
}

/// Threads in a block (unless `ANIMATS_GPU_BLOCK` says otherwise).
const BLOCK: u32 = 128;

/// Threads a block for a launch of `threads` on a GPU of `sms`
/// multiprocessors: `set` where `ANIMATS_GPU_BLOCK` set it; else the
/// whole warps a block, up to 128 (`BLOCK`), that put the fewest warps on the
/// busiest multiprocessor, the larger block where two tie. The GPU deals
/// a launch's blocks out to its multiprocessors in turn, so `b` warps a
/// block put ⌈⌈warps / b⌉ / sms⌉ × b on the busiest, and with warps that
/// take alike the launch lasts as long as that one's. 4,096 creatures in
/// blocks of 128 ran on 32 of an H200's 132 multiprocessors, four warps
/// on each, the rest idle; in blocks of 32, one warp on each of 128. A
/// large launch keeps 128 (65,536: 16 warps on the busiest in
/// blocks of one warp or four alike). A thread's work, its arithmetic and
/// its bits are the same in any block.
pub fn threads_a_block(threads: i64, sms: i64, set: Option<u32>) -> u32 {
    if let Some(block) = set {
        return block;
    }
    let warps = (threads.max(1) as u64).div_ceil(32);
    let sms = sms.max(1) as u64;
    let busiest = |b: u64| warps.div_ceil(b).div_ceil(sms) * b;
    let most = u64::from(BLOCK / 32);
    // Ties go to the larger block: searched from the largest down, a
    // smaller one taken only when it puts strictly fewer on the busiest.
    let b = (1..=most).rev().fold(
        most,
        |best, b| {
            if busiest(b) < busiest(best) {
                b
            } else {
                best
            }
        },
    );
    32 * b as u32
}

/// One thread per creature, in blocks of `threads`.
fn config(creatures: i64, threads: u32) -> Result<LaunchConfig, String> {
    let blocks = (creatures.max(0) as u64).div_ceil(threads as u64).max(1);
    Ok(LaunchConfig {
        grid_dim: (
            u32::try_from(blocks).map_err(|_| "too many creatures for one launch")?,
            1,
            1,
        ),
        block_dim: (threads, 1, 1),
        shared_mem_bytes: 0,
    })
}

/// Array `a` (of doubles) copied back from the device.
fn download_f64(s: &Arc<CudaStream>, on: &[OnDevice], a: Array) -> Result<Vec<f64>, String> {
    match &on[a as usize] {
        OnDevice::F64(x) => s.clone_dtoh(x).map_err(err("copying from the GPU")),
        _ => Err(format!("{a:?} is not an array of doubles")),
    }
}

/// Array `a` (of 64-bit integers) copied back from the device.
fn download_i64(s: &Arc<CudaStream>, on: &[OnDevice], a: Array) -> Result<Vec<i64>, String> {
    match &on[a as usize] {
        OnDevice::I64(x) => s.clone_dtoh(x).map_err(err("copying from the GPU")),
        _ => Err(format!("{a:?} is not an array of 64-bit integers")),
    }
}

enum OnDevice {
    F64(CudaSlice<f64>),
    I32(CudaSlice<i32>),
    I64(CudaSlice<i64>),
}

/// The C's `an_batch` holding device pointers, passed by value.
#[repr(transparent)]
struct DeviceBatch(Raw);

// SAFETY: a plain #[repr(C)] struct of pointers (device addresses), numbers
// and ints, the layout of the kernel's `an_batch`.
unsafe impl DeviceRepr for DeviceBatch {}

/// NVRTC's options for `sm_{major}{minor}`: IEEE division and square
/// root, no flush to zero; in strict mode no contraction into fused
/// multiply-adds, in fast mode contraction.
fn options((major, minor): (i32, i32), mode: Mode) -> Vec<String> {
    vec![
        format!("--gpu-architecture=sm_{major}{minor}"),
        match mode {
            Mode::Strict => "--fmad=false".to_string(),
            Mode::Fast => "--fmad=true".to_string(),
        },
        "--prec-div=true".to_string(),
        "--prec-sqrt=true".to_string(),
        "--ftz=false".to_string(),
    ]
}

/// NVRTC's version, as `major.minor` (part of a kept kernel's name).
fn nvrtc_version() -> String {
    let (mut major, mut minor) = (0, 0);
    // SAFETY: NVRTC is loaded (checked in `open`); two ints receive it.
    let got = unsafe { cudarc::nvrtc::sys::nvrtcVersion(&mut major, &mut minor) };
    if got == cudarc::nvrtc::sys::nvrtcResult::NVRTC_SUCCESS {
        format!("{major}.{minor}")
    } else {
        "unknown".into()
    }
}

/// NVRTC: the kernel `source` to a CUBIN for `sm_{major}{minor}`.
fn compile(
    source: &str,
    options: &[String],
    (major, minor): (i32, i32),
) -> Result<Vec<u8>, String> {
    use cudarc::nvrtc::{result, sys};
    let src = std::ffi::CString::new(source).map_err(|e| format!("the kernel's source: {e}"))?;
    let prog = result::create_program(&src, None).map_err(|e| format!("NVRTC: {e}"))?;
    // SAFETY: `prog` is a live program; the options are valid C strings.
    let compiled = unsafe { result::compile_program(prog, options) };
    if let Err(e) = compiled {
        // SAFETY: as above.
        let log = unsafe { result::get_program_log(prog) }.unwrap_or_default();
        let log: String = log.iter().map(|&c| c as u8 as char).collect();
        // SAFETY: as above; destroyed once.
        let _ = unsafe { result::destroy_program(prog) };
        return Err(format!(
            "NVRTC could not compile the step for sm_{major}{minor}: {e}\n{log}"
        ));
    }
    let mut size = 0usize;
    // SAFETY: `prog` compiled; `size` receives the CUBIN's length.
    let got = unsafe { sys::nvrtcGetCUBINSize(prog, &mut size) };
    let mut cubin = vec![0u8; size];
    // SAFETY: `cubin` holds `size` bytes.
    let got2 = unsafe { sys::nvrtcGetCUBIN(prog, cubin.as_mut_ptr().cast()) };
    // SAFETY: destroyed once.
    let _ = unsafe { result::destroy_program(prog) };
    if got != sys::nvrtcResult::NVRTC_SUCCESS
        || got2 != sys::nvrtcResult::NVRTC_SUCCESS
        || size == 0
    {
        return Err(format!(
            "NVRTC gave no CUBIN for sm_{major}{minor} ({got:?}, {got2:?})"
        ));
    }
    Ok(cubin)
}

#[cfg(test)]
mod tests {
    #[test]
    fn the_kernel_source_has_every_piece_and_no_includes() {
        let s = super::source();
        for needle in [
            "an_atan2",
            "an_sin",
            "an_step_creature",
            "an_probe",
            "an_evaluate_creature",
            "animats_evaluate_kernel",
            "animats_step_kernel",
        ] {
            assert!(s.contains(needle), "{needle}");
        }
        assert!(!s.contains("#include"));
    }

    use super::{config, parse_specialise, threads_a_block, Tuning, BLOCK};

    #[test]
    fn specialising_is_on_unless_turned_off_and_other_values_are_refused_by_name() {
        for on in [None, Some(""), Some("1"), Some(" 1 ")] {
            assert_eq!(parse_specialise(on), Ok(true), "{on:?}");
        }
        assert_eq!(parse_specialise(Some("0")), Ok(false));
        for bad in ["yes", "2", "off"] {
            let e = parse_specialise(Some(bad)).unwrap_err();
            assert!(
                e.contains("ANIMATS_GPU_SPECIALISE") && e.contains(bad),
                "{e}"
            );
        }
    }

    #[test]
    fn the_tuning_knobs_take_what_a_gpu_can_run_and_name_what_they_refuse() {
        let t = |r, b| Tuning::parse(r, b);
        assert_eq!(
            t(None, None),
            Ok(Tuning {
                regs: None,
                block: None
            })
        );
        assert_eq!(
            t(Some("128"), Some("256")),
            Ok(Tuning {
                regs: Some(128),
                block: Some(256)
            })
        );
        assert_eq!(
            t(Some(" 16 "), Some("1024")),
            Ok(Tuning {
                regs: Some(16),
                block: Some(1024)
            })
        );
        assert_eq!(
            t(Some("255"), Some("32")),
            Ok(Tuning {
                regs: Some(255),
                block: Some(32)
            })
        );
        for (r, b, name) in [
            (Some("15"), None, "ANIMATS_GPU_REGS"),
            (Some("256"), None, "ANIMATS_GPU_REGS"),
            (Some("lots"), None, "ANIMATS_GPU_REGS"),
            (Some("-1"), None, "ANIMATS_GPU_REGS"),
            (None, Some("100"), "ANIMATS_GPU_BLOCK"),
            (None, Some("0"), "ANIMATS_GPU_BLOCK"),
            (None, Some("2048"), "ANIMATS_GPU_BLOCK"),
            (None, Some(""), "ANIMATS_GPU_BLOCK"),
        ] {
            let e = t(r, b).expect_err("refused");
            assert!(e.starts_with(name), "{e}");
            assert!(e.contains("got"), "{e}");
        }
    }

    #[test]
    fn a_launch_puts_the_fewest_warps_on_its_busiest_multiprocessor() {
        // An H200's 132 multiprocessors: (threads, block, warps on the
        // busiest multiprocessor).
        for (threads, block, busiest) in [
            (1, 32, 1),
            (512, 32, 1),
            (2_048, 32, 1),
            (4_096, 32, 1),
            (4_225, 64, 2),
            (8_192, 64, 2),
            (8_448, 64, 2),
            (16_384, 128, 4),
            (16_896, 128, 4),
            (65_536, BLOCK, 16),
            (10_000_000, BLOCK, 2_368),
        ] {
            let b = threads_a_block(threads, 132, None);
            assert_eq!(b, block, "{threads} threads");
            let on_busiest = |b: u32| {
                let blocks = (threads as u64).div_ceil(u64::from(b));
                blocks.div_ceil(132) * u64::from(b / 32)
            };
            assert_eq!(on_busiest(b), busiest, "{threads} threads");
            // No other block puts fewer there, nor as few in a larger block.
            for other in (32..=BLOCK).step_by(32) {
                assert!(on_busiest(other) >= on_busiest(b), "{threads}: {other}");
                if other > b {
                    assert!(on_busiest(other) > on_busiest(b), "{threads}: {other}");
                }
            }
        }
        // Blocks of 128 left 100 of the 132 idle for 4,096 creatures.
        assert_eq!((4_096u64).div_ceil(128), 32);
        // Set by ANIMATS_GPU_BLOCK: as set, whatever the launch.
        assert_eq!(threads_a_block(512, 132, Some(256)), 256);
        assert_eq!(threads_a_block(0, 0, None), 32);
    }

    #[test]
    fn a_launch_covers_every_creature_in_blocks_of_the_size_asked() {
        for (creatures, block, blocks) in [
            (0, 128, 1),
            (1, 128, 1),
            (128, 128, 1),
            (129, 128, 2),
            (65_536, 64, 1024),
            (65_537, 256, 257),
        ] {
            let c = config(creatures, block).unwrap();
            assert_eq!(c.block_dim, (block, 1, 1));
            assert_eq!(c.grid_dim, (blocks, 1, 1));
        }
    }
}
