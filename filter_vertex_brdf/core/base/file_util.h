#pragma once
// Small filesystem helpers shared by the input and output code.
#include <string>

namespace vbrdf {

std::string file_name_of(const std::string &path);       // "a/b/c.png" -> "c.png"
std::string directory_of(const std::string &path);       // "a/b/c.png" -> "a/b" ("." if none)
std::string join_path(const std::string &dir, const std::string &name);  // absolute name wins
bool file_exists(const std::string &path);
std::string to_lower(std::string s);
std::string strip_extension(const std::string &path);  // "a/b.c/d.png" -> "a/b.c/d"
std::string extension_of(const std::string &path);     // "a/B.LP" -> "lp" (lower case; "" if none)

} // namespace vbrdf
