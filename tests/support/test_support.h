// Helpers shared by the test executables: where the test meshes and the built CLI live, and
// meshes generated in code for the edge cases no file covers.
#pragma once

#include "polycube/mesh.h"

#include <string>
#include <vector>

namespace polycube::test {

// Absolute path of a file in tests/data/.
std::string data_path(const std::string& name);

// Absolute path of a file in examples/.
std::string example_path(const std::string& name);

// Absolute path of the built `polycube` binary.
std::string binary_path();

// A fresh empty directory under the system temp dir, removed by nobody (ctest runs are short).
std::string temp_dir(const std::string& tag);

// Runs a shell command; returns its exit code and fills stdout/stderr when given.
int run_command(const std::string& command, std::string* out = nullptr, std::string* err = nullptr);

}  // namespace polycube::test
