// Forced include (-include) of mmrtmItkDicomLoader.cxx under clang only (the
// fuzz build). Debian's ITK 5.2 generated its compiler detection for GCC
// alone and stops with "Unsupported compiler" under clang. Clang is
// GCC-compatible, so the detection runs here once as if under the GCC 12
// that built Debian's ITK (clang 14 has every C++17 feature it checks for);
// its include guard keeps ITK's own later include from running it again.
#pragma once
#pragma push_macro("__clang__")
#pragma push_macro("__GNUC__")
#pragma push_macro("__GNUC_MINOR__")
#undef __clang__
#undef __GNUC__
#undef __GNUC_MINOR__
#define __GNUC__ 12
#define __GNUC_MINOR__ 2
#include <itk_compiler_detection.h>
#pragma pop_macro("__GNUC_MINOR__")
#pragma pop_macro("__GNUC__")
#pragma pop_macro("__clang__")
