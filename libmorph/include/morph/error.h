// The exceptions thrown by libmorph. The library never prints and never exits: every
// failure is one of these, with a message that names the file or element concerned.
#pragma once

#include <stdexcept>
#include <string>

namespace morph {

/// Base of every libmorph exception.
class error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Input that cannot be used as given: a malformed file, a bad structuring-element
/// spec, a bad pipeline line, a bad option value.
class input_error : public error {
 public:
  using error::error;
};

/// A file that cannot be opened, read or written (missing, permissions, disk full).
class io_error : public error {
 public:
  using error::error;
};

/// Input larger than the documented limits (counts, valences, memory guard).
class limit_error : public input_error {
 public:
  using input_error::input_error;
};

/// A mesh that is well formed but is not a valid operand: not closed, not 2-manifold,
/// inconsistently oriented, or with degenerate facets.
class invalid_mesh : public error {
 public:
  using error::error;
};

/// A closed, well-formed mesh that is not convex (within the documented tolerance).
class not_convex : public invalid_mesh {
 public:
  using invalid_mesh::invalid_mesh;
};

}  // namespace morph
