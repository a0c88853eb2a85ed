// Non-owning views of C-contiguous float64, int64 and bool arrays that Python owns (numpy).
// The core never allocates in the hot path and owns no Python object: the bindings
// (bindings.cpp) check every array's dtype, shape and contiguity, then hand these views in.
#pragma once

#include <cstdint>

namespace mt {

using idx = std::int64_t;

/// A 1-D float64 array (or one row of a 2-D one).
struct Vec {
  double* d = nullptr;
  idx n = 0;
  double& operator[](idx i) const { return d[i]; }
};

/// to[i] = from[i] for i < from.n.
inline void copy(Vec from, Vec to) {
  for (idx i = 0; i < from.n; ++i) to[i] = from[i];
}

/// A 2-D float64 array, row-major.
struct Mat {
  double* d = nullptr;
  idx rows = 0;
  idx cols = 0;
  double& operator()(idx i, idx j) const { return d[i * cols + j]; }
  Vec row(idx i) const { return Vec{d + i * cols, cols}; }
  Vec flat() const { return Vec{d, rows * cols}; }  // every element, row by row
};

/// A 3-D float64 array (n, r, c), row-major: a stack of matrices.
struct Mats {
  double* d = nullptr;
  idx n = 0;
  idx rows = 0;
  idx cols = 0;
  double& operator()(idx i, idx r, idx c) const { return d[(i * rows + r) * cols + c]; }
  Mat mat(idx i) const { return Mat{d + i * rows * cols, rows, cols}; }
};

/// A 2-D float64 array with C columns known at compile time (3-vectors, 3×3 matrices, wrench
/// rows): the index arithmetic folds to constants.
template <idx C>
struct MatC {
  double* d = nullptr;
  idx rows = 0;
  double& operator()(idx i, idx j) const { return d[i * C + j]; }
  Vec row(idx i) const { return Vec{d + i * C, C}; }
};

/// A stack (n, R, C) of matrices of a shape known at compile time (mount axes, stiffness).
template <idx R, idx C>
struct MatsRC {
  double* d = nullptr;
  idx n = 0;
  double& operator()(idx i, idx r, idx c) const { return d[(i * R + r) * C + c]; }
  MatC<C> mat(idx i) const { return MatC<C>{d + i * R * C, R}; }
};

/// A stack (n, rows, C) of row blocks with C columns known at compile time.
template <idx C>
struct StackC {
  double* d = nullptr;
  idx n = 0;
  idx rows = 0;
  double& operator()(idx i, idx r, idx c) const { return d[(i * rows + r) * C + c]; }
  MatC<C> mat(idx i) const { return MatC<C>{d + i * rows * C, rows}; }
};

using M3 = MatC<3>;          // (rows, 3): 3×3 matrices, rows of 3-vectors
using M6 = MatC<6>;          // (rows, 6): wrench rows
using M33s = MatsRC<3, 3>;   // (n, 3, 3)

/// A 1-D int64 array.
struct IVec {
  const idx* d = nullptr;
  idx n = 0;
  idx operator[](idx i) const { return d[i]; }
};

/// A 1-D bool array (numpy's one-byte bool).
struct BVec {
  const bool* d = nullptr;
  idx n = 0;
  bool operator[](idx i) const { return d[i]; }
};

}  // namespace mt
