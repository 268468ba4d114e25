// GCC 12 warns that the AVX-512 intrinsics' _mm512_undefined_pd() values are
// used uninitialized wherever Eigen's AVX-512 packet code inlines them (GCC bug
// 105593, fixed in GCC 13): hundreds of false reports from <immintrin.h> alone.
// CMakeLists.txt force-includes this header first in every file of a GCC 12
// build with AVX-512, so that <immintrin.h> is read once, here, with those two
// warnings off for its own lines only; they stay on for the project's code.
#pragma once

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wuninitialized"
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include <immintrin.h>
#pragma GCC diagnostic pop
