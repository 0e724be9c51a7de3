#!/usr/bin/env python3
"""Compiles the GPU kernel (crates/gpu/kernel) with NVRTC as
`animats_gpu::Device::open` does (the same headers in the same order, the
same strict options) for a GPU architecture, with no GPU: NVRTC only needs
its own libraries, which the PyPI package nvidia-cuda-nvrtc provides. Prints
ptxas's registers, stack and spills for each entry of the whole kernels
(the flat floor's, terrain's and sphere contact's, the flat floor's with
implicit Euler) and of one specialised for a batch of walkers; exit 1 if NVRTC refuses
the kernel (its log printed), 2 if NVRTC cannot be found.

    python3 -m venv target/venv-nvrtc
    target/venv-nvrtc/bin/pip install nvidia-cuda-nvrtc
    target/venv-nvrtc/bin/python bench/nvrtc.py [--quick] [sm_90 ...]

With options after `--` (as `gpu_evaluate` prints them for its batch, a
kernel specialised for it: `GPU kernel options: -DAN_FLAT_ONLY
-DAN_ONLY_INTEGRATOR=3 -DAN_ABSENT=32511`), that one kernel is compiled
instead, through ptxas, its report printed.

With --quick, every kernel is compiled to PTX only (the architecture's
virtual `compute_XX`: NVRTC's front end and optimiser, about 12 s a kernel
on a 2-core Xeon against about 38 s through ptxas), and only the flat
floor's (the commonest) through ptxas for the real architecture, its report
printed. CI runs that, so that the kernel keeps compiling where the tests
cannot run it (they compile the same C with the C compiler instead)."""

import ctypes
import glob
import os
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
KERNEL = os.path.join(ROOT, "crates", "gpu", "kernel")
# In the order of crates/gpu/src/cuda.rs's `source`.
PARTS = ["libm.h", "terrain.h", "spheres.h", "trig.h", "exp.h", "step.h", "eval.h", "kernel.cu"]
# As crates/gpu/src/cuda.rs's `options`, with ptxas's report.
OPTIONS = ["--fmad=false", "--prec-div=true", "--prec-sqrt=true", "--ftz=false", "--ptxas-options=-v"]


def nvrtc():
    """NVRTC from the nvidia-cuda-nvrtc package (or $NVRTC_LIB)."""
    folders = [os.environ["NVRTC_LIB"]] if os.environ.get("NVRTC_LIB") else []
    try:
        import nvidia  # the namespace package nvidia-cuda-nvrtc installs into

        for base in nvidia.__path__:
            folders += glob.glob(os.path.join(base, "*", "lib"))
    except ImportError:
        pass
    for folder in folders:
        libs = sorted(glob.glob(os.path.join(folder, "libnvrtc.so*")))
        builtins = sorted(glob.glob(os.path.join(folder, "libnvrtc-builtins.so*")))
        if libs and builtins:
            # The builtins first: NVRTC loads them by name at compile time.
            ctypes.CDLL(builtins[-1], mode=ctypes.RTLD_GLOBAL)
            return ctypes.CDLL(libs[-1])
    sys.exit("nvrtc.py: no NVRTC found: pip install nvidia-cuda-nvrtc (or set NVRTC_LIB to its folder)")


def source():
    text = []
    for part in PARTS:
        with open(os.path.join(KERNEL, part)) as f:
            text.append("\n".join(l for l in f.read().split("\n") if not l.lstrip().startswith("#include")))
    return "\n".join(text)


def compile_for(lib, arch, src, extra):
    prog = ctypes.c_void_p()
    if lib.nvrtcCreateProgram(ctypes.byref(prog), src.encode(), b"kernel.cu", 0, None, None) != 0:
        return False, "nvrtcCreateProgram failed"
    opts = [f"--gpu-architecture={arch}"] + OPTIONS + extra
    arr = (ctypes.c_char_p * len(opts))(*[o.encode() for o in opts])
    result = lib.nvrtcCompileProgram(prog, len(opts), arr)
    size = ctypes.c_size_t()
    lib.nvrtcGetProgramLogSize(prog, ctypes.byref(size))
    log = ctypes.create_string_buffer(size.value)
    lib.nvrtcGetProgramLog(prog, log)
    out = ctypes.c_size_t()
    if arch.startswith("compute_"):
        lib.nvrtcGetPTXSize(prog, ctypes.byref(out))
    else:
        lib.nvrtcGetCUBINSize(prog, ctypes.byref(out))
    lib.nvrtcDestroyProgram(ctypes.byref(prog))
    return result == 0 and out.value > 0, log.value.decode(errors="replace")


def main():
    lib = nvrtc()
    major, minor = ctypes.c_int(), ctypes.c_int()
    lib.nvrtcVersion(ctypes.byref(major), ctypes.byref(minor))
    src = source()
    failed = False
    args = sys.argv[1:]
    given = None
    if "--" in args:
        given = args[args.index("--") + 1:]
        args = args[:args.index("--")]
    quick = "--quick" in args
    args = [a for a in args if a != "--quick"]
    def report(to, name, extra):
        """Compiles the kernel with `extra` for `to`; prints what ptxas says."""
        ok, log = compile_for(lib, to, src, extra)
        print(f"NVRTC {major.value}.{minor.value}, {to}, {name}: {'compiled' if ok else 'REFUSED'}")
        for line in log.splitlines():
            if not ok or "entry function" in line or "registers" in line or "spill" in line or "warning" in line:
                print("  " + line.strip())
        return ok

    for arch in args or ["sm_90"]:
        if given is not None:
            failed |= not report(arch, " ".join(given), given)
            continue
        # As crates/gpu/src/cuda.rs's whole kernels: the flat floor's,
        # terrain's and sphere contact's (on the flat floor); then the flat
        # floor's with implicit Euler (its other two are compiled alike).
        kinds = [
            ("flat floor", ["-DAN_FLAT_ONLY"]),
            ("terrain", []),
            ("sphere contact", ["-DAN_FLAT_ONLY", "-DAN_SPHERES"]),
            ("implicit Euler, flat floor", ["-DAN_FLAT_ONLY", "-DAN_WITH_IMPLICIT"]),
            # A kernel specialised for a batch (src/cuda.rs, `Special`): the
            # walker's, as gpu_evaluate prints it.
            ("specialised for walkers", ["-DAN_FLAT_ONLY", "-DAN_ONLY_INTEGRATOR=3", "-DAN_ABSENT=65279"]),
        ]
        for i, (kernel, extra) in enumerate(kinds):
            # (--quick: PTX only but for the first.)
            to = arch.replace("sm_", "compute_") if quick and i > 0 else arch
            failed |= not report(to, kernel, extra)
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
