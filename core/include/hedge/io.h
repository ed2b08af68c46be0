// Reading and writing shapes: OFF, OBJ, PLY (ASCII and binary), STL (ASCII and binary).
// Files are read into a Soup; errors name the file, the line or byte offset, and what was
// expected.
#pragma once

#include <string>
#include <string_view>

#include "hedge/soup.h"

namespace hedge {

enum class FileFormat { off, obj, ply, stl };

struct WriteOptions {
  bool binary = true;  //!< PLY and STL: binary (little endian) or ASCII
};

//! Format from the file name's extension (case-insensitive); throws Error when unknown.
FileFormat format_from_path(const std::string& path);

Soup read_mesh(const std::string& path);
void write_mesh(const Soup& soup, const std::string& path, const WriteOptions& options = {});

// Per format, from/to memory; `name` is used in error messages.
Soup read_off(std::string_view bytes, const std::string& name);
Soup read_obj(std::string_view bytes, const std::string& name);
Soup read_ply(std::string_view bytes, const std::string& name);
Soup read_stl(std::string_view bytes, const std::string& name);
std::string write_off(const Soup& soup);
std::string write_obj(const Soup& soup);
std::string write_ply(const Soup& soup, bool binary);
std::string write_stl(const Soup& soup, bool binary);

}  // namespace hedge
