"""Says whose code a libFuzzer finding is in, from the target's log.

Usage: classify_finding.py LOG   (prints "ours: FRAME" or "third-party: FRAME")

The first stack frame of the report that is not libFuzzer's, a sanitizer's,
the C library's or an allocator's decides: a frame in the fuzz program
itself (the project's code is linked into it statically) is ours; a frame
in a shared library (VTK, metaio, GDCM, OpenJPEG, zlib, libstdc++) is
third-party. run_fuzzers.sh uses it when MMRTM_FUZZ_FAIL_ON=ours (ctest's
fuzz-short; Documentation/reliability.md says why).
"""
import re
import sys

REPORT = re.compile(r"ERROR: (AddressSanitizer|LeakSanitizer|libFuzzer|UndefinedBehaviorSanitizer)|runtime error:")
FRAME = re.compile(r"^\s*#\d+ 0x[0-9a-f]+\s+(?:in (?P<func>.*?)\s+)?(?P<where>\(?/.*)$")
SKIP = re.compile(r"fuzzer::|__sanitizer|__asan|__interceptor|__lsan|__ubsan|asan_|printf_common|internal_strlen|"
                  r"^operator new|^operator delete|^malloc$|^calloc$|^realloc$|^posix_memalign$|^free$|"
                  r"^v?snprintf$|__snprintf_chk|^v?sprintf$|^strlen$|^strn?cat$|^strn?cpy$|^mem(cpy|move|set|cmp)$|"
                  r"__pthread_kill|^raise$|^abort$|__assert_fail|^_start$|__libc_start|^main$")


def classify(lines):
    seen_report = False
    for line in lines:
        if not seen_report:
            seen_report = bool(REPORT.search(line))
            continue
        m = FRAME.match(line)
        if not m:
            continue
        func, where = m.group("func") or "", m.group("where")
        if SKIP.search(func) or "libc.so" in where:
            continue
        module = re.search(r"\((/.*?)(\+0x|\))", where)
        in_library = bool(module and ".so" in module.group(1).rsplit("/", 1)[-1])
        if "LLVMFuzzerTestOneInput" in func or "mmrtm::" in func or (module and not in_library):
            return "ours", func
        if in_library:
            return "third-party", f"{func} {module.group(1)}"
        return "ours", func  # a source path without a library: the program's own code
    return "ours", "no stack frame to tell by"


if __name__ == "__main__":
    with open(sys.argv[1], errors="replace") as f:
        kind, frame = classify(f.readlines())
    print(f"{kind}: {frame}")
