"""classify_finding.py on report excerpts of real findings (Documentation/reliability.md):
the first frame past libFuzzer, the sanitizers, libc and the allocator decides."""
import unittest

from classify_finding import classify

GDCM_ASSERT = """==1== ERROR: libFuzzer: deadly signal
    #0 0x55 in __sanitizer_print_stack_trace (/b/bin/fuzz-dicom+0x18f2b1)
    #1 0x55 in fuzzer::PrintStackTrace() (/b/bin/fuzz-dicom+0x101c08)
    #6 0x7f in abort stdlib/./stdlib/abort.c:79:7
    #8 0x7f in __assert_fail assert/./assert/assert.c:103:3
    #9 0x7f in bool gdcm::Reader::InternalReadCommon<T>(T const&) (/lib/x86_64-linux-gnu/libgdcmDSED.so.3.0+0x9de68)
    #12 0x55 in mmrtm::ScanFolder(std::string const&) /src/VTKModule/IO/mmrtmItkDicomLoader.cxx:88:16
"""
OPENJPEG_OOM = """==2== ERROR: libFuzzer: out-of-memory (used: 2099Mb; limit: 2048Mb)
    #0 0x56 in posix_memalign (/b/bin/fuzz-dicom+0x1bfed7)
    #1 0x7e  (/lib/x86_64-linux-gnu/libopenjp2.so.7+0x4b878)
"""
STDCXX_READ = """==3==ERROR: AddressSanitizer: SEGV on unknown address 0x000000000008
    #0 0x7f in std::istream::read(char*, long) (/lib/x86_64-linux-gnu/libstdc++.so.6+0x11718d)
    #1 0x7f  (/lib/x86_64-linux-gnu/libvtkIOImage-9.1.so.1+0x64619)
"""
OUR_CHECK = """==4== ERROR: libFuzzer: deadly signal
    #6 0x7f in abort stdlib/./stdlib/abort.c:79:7
    #7 0x55 in LLVMFuzzerTestOneInput /src/Testing/Fuzz/FuzzVolumeFile.cpp:69:69
"""
OUR_OVERFLOW = """==5==ERROR: AddressSanitizer: heap-buffer-overflow on address 0x6
READ of size 4 at 0x6 thread T0
    #0 0x55 in mmrtm::TransferFunctionView::FindEntry(float) const /src/cuda/include/mmrtm/transfer_function.h:80:3
    #1 0x55 in LLVMFuzzerTestOneInput /src/Testing/Fuzz/FuzzSceneJson.cpp:60:3
"""


class ClassifyFinding(unittest.TestCase):
    def test_third_party(self):
        for log, frame in ((GDCM_ASSERT, "gdcm::Reader"), (OPENJPEG_OOM, "libopenjp2"), (STDCXX_READ, "libstdc++")):
            kind, where = classify(log.splitlines())
            self.assertEqual(kind, "third-party", log)
            self.assertIn(frame, where)

    def test_ours(self):
        for log, frame in ((OUR_CHECK, "LLVMFuzzerTestOneInput"), (OUR_OVERFLOW, "FindEntry")):
            kind, where = classify(log.splitlines())
            self.assertEqual(kind, "ours", log)
            self.assertIn(frame, where)

    def test_no_stack_counts_as_ours(self):
        self.assertEqual(classify(["==6== ERROR: libFuzzer: timeout after 21 seconds"])[0], "ours")


if __name__ == "__main__":
    unittest.main()
