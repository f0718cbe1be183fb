// Writing outputs atomically: everything is first written to a temporary file next to the
// destination and renamed over it only once complete, so a failure (exception, full disk, crash)
// never leaves a half-written output and never destroys the previous version of the file.
#pragma once

#include <functional>
#include <ostream>
#include <string>

namespace polycube {

// Calls writer(temp_path) with a fresh, empty temporary file in the directory of path (named
// `.<name>.tmp-<pid>-<n>`), then flushes it to disk and renames it over path.
//   path    destination file; its directory must exist and be writable
//   writer  fills the file at temp_path (may truncate and rewrite it); signals failure by throwing
// If writer throws, the temporary file is removed and the exception propagates unchanged; path is
// left as it was. The new file gets default permissions, and a symbolic link at path is replaced
// rather than followed (as rename(2) does). Throws OutputError("cannot write <path>: <reason>") when the directory does
// not exist or is not writable, path is a directory, or the final rename fails.
void write_atomically(const std::string& path, const std::function<void(const std::string& temp_path)>& writer);

// write_atomically for stream output: writer gets an std::ostream on the temporary file (opened
// in binary mode, so bytes are written exactly as given). Throws OutputError if the stream is in a
// failed state after writer returns or after closing (e.g. disk full).
void write_text_atomically(const std::string& path, const std::function<void(std::ostream& out)>& writer);

}  // namespace polycube
