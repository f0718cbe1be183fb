// Exception hierarchy of the engine and its I/O. Library code throws these; only cli/ prints them
// and chooses exit codes. Messages are one line, name the problem and carry the measured values.
#pragma once

#include <stdexcept>
#include <string>

namespace polycube {

// Base of everything polycube throws on purpose.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A file that cannot be opened, parsed or holds invalid data (NaN, bad indices, truncation).
class InputError : public Error {
 public:
  using Error::Error;
};

// A mesh that was read but is not a closed, connected, 2-manifold, oriented triangle surface.
class MeshError : public Error {
 public:
  using Error::Error;
};

// An output that cannot be written.
class OutputError : public Error {
 public:
  using Error::Error;
};

// A stage of the method that could not produce a valid result within its limits.
class AlgorithmError : public Error {
 public:
  using Error::Error;
};

}  // namespace polycube
