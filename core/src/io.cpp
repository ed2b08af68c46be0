// Reading and writing mesh files: format from the extension, whole-file reads, and writes
// that go through a temporary file so a failure never leaves half a file behind.
#include "hedge/io.h"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <string_view>

#include "hedge/error.h"
#include "io_detail.h"

namespace hedge {

namespace io_detail {

void fail_line(const std::string& name, std::size_t line, const std::string& what) {
  throw Error(name + ": line " + std::to_string(line) + ": " + what);
}

void fail_byte(const std::string& name, std::size_t offset, const std::string& what) {
  throw Error(name + ": byte " + std::to_string(offset) + ": " + what);
}

std::string quote(std::string_view token, bool at_end_of_file) {
  if (token.empty()) return at_end_of_file ? "end of file" : "end of line";
  constexpr std::size_t kMax = 40;
  std::string out = "'";
  for (std::size_t i = 0; i < token.size() && i < kMax; ++i) {
    unsigned char c = static_cast<unsigned char>(token[i]);
    // Binary garbage in a message helps nobody and can break a terminal.
    if (c < 32 || c >= 127) {
      static const char* hex = "0123456789abcdef";
      out += "\\x";
      out += hex[c >> 4];
      out += hex[c & 15];
    } else {
      out += static_cast<char>(c);
    }
  }
  if (token.size() > kMax) out += "...";
  out += "'";
  return out;
}

void check_soup(const Soup& soup, const std::string& name) {
  try {
    soup.check();
  } catch (const Error& e) {
    throw Error(name + ": " + e.what());
  }
}

template <class T>
static bool parse_out_of_range_impl(std::string_view token, T& out) {
  // from_chars reports values beyond the type's range without a value; strtod gives the
  // usual 0, denormal or infinity, which is what a file with 1e-50 in it means.
  std::string copy(token);
  char* stop = nullptr;
  double v = std::strtod(copy.c_str(), &stop);
  if (stop != copy.c_str() + copy.size()) return false;
  out = static_cast<T>(v);
  return true;
}

bool parse_out_of_range(std::string_view token, float& out) { return parse_out_of_range_impl(token, out); }
bool parse_out_of_range(std::string_view token, double& out) { return parse_out_of_range_impl(token, out); }

std::array<std::uint8_t, 4> ColorView::operator[](std::size_t i) const {
  std::array<std::uint8_t, 4> rgba{};
  if (channel->scalar == ScalarType::u8) {
    std::memcpy(rgba.data(), channel->data.data() + 4 * i, 4);
  } else {
    const float* f = channel->as<float>() + 4 * i;
    for (int k = 0; k < 4; ++k) rgba[k] = color_from_real(f[k]);
  }
  return rgba;
}

ColorView find_color(const Soup& soup, Domain domain) {
  ColorView view;
  const Channel* c = soup.find("color", domain);
  if (c && c->components == 4 && (c->scalar == ScalarType::u8 || c->scalar == ScalarType::f32)) view.channel = c;
  return view;
}

const Channel* find_channel(const Soup& soup, const std::string& name, Domain domain, ScalarType scalar,
                            int components) {
  const Channel* c = soup.find(name, domain);
  return c && c->scalar == scalar && c->components == components ? c : nullptr;
}

}  // namespace io_detail

namespace {

std::string lower(std::string s) {
  for (char& c : s)
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
  return s;
}

std::string system_reason(int error) { return std::strerror(error); }

//! A file's bytes: mapped from the page cache when it is a regular file, read into memory
//! otherwise (pipes and special files). Mapping spares a copy of the whole file into fresh
//! pages, which on the dragon's 34 MB were a fifth of a decimation's page faults.
class FileBytes {
 public:
  explicit FileBytes(const std::string& path) {
    int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) fail(path, errno);
    struct stat info {};
    if (::fstat(fd, &info) == 0 && S_ISREG(info.st_mode) && info.st_size > 0) {
      auto size = static_cast<std::size_t>(info.st_size);
      void* p = ::mmap(nullptr, size, PROT_READ, MAP_PRIVATE | MAP_POPULATE, fd, 0);
      if (p != MAP_FAILED) {
        ::close(fd);
        mapped_ = p;
        size_ = size;
        return;
      }
    }
    read_all(path, fd);
  }
  FileBytes(const FileBytes&) = delete;
  FileBytes& operator=(const FileBytes&) = delete;
  ~FileBytes() {
    if (mapped_) ::munmap(mapped_, size_);
  }

  std::string_view view() const {
    return mapped_ ? std::string_view(static_cast<const char*>(mapped_), size_) : std::string_view(copy_);
  }

 private:
  [[noreturn]] static void fail(const std::string& path, int error) {
    throw Error("cannot open " + path + ": " + system_reason(error));
  }

  void read_all(const std::string& path, int fd) {
    char buffer[1 << 16];
    for (;;) {
      ssize_t n = ::read(fd, buffer, sizeof buffer);
      if (n < 0 && errno == EINTR) continue;
      if (n < 0) {
        int error = errno;
        ::close(fd);
        fail(path, error);
      }
      if (n == 0) break;
      copy_.append(buffer, static_cast<std::size_t>(n));
    }
    ::close(fd);
  }

  void* mapped_ = nullptr;
  std::size_t size_ = 0;
  std::string copy_;
};

}  // namespace

FileFormat format_from_path(const std::string& path) {
  std::size_t slash = path.find_last_of('/');
  std::size_t dot = path.find_last_of('.');
  std::string extension =
      dot == std::string::npos || (slash != std::string::npos && dot < slash) ? "" : lower(path.substr(dot));
  if (extension == ".off") return FileFormat::off;
  if (extension == ".obj") return FileFormat::obj;
  if (extension == ".ply") return FileFormat::ply;
  if (extension == ".stl") return FileFormat::stl;
  if (extension.empty()) throw Error(path + ": the file name has no extension; expected .off, .obj, .ply or .stl");
  throw Error(path + ": unknown file extension '" + path.substr(dot) + "'; expected .off, .obj, .ply or .stl");
}

Soup read_mesh(const std::string& path) {
  FileFormat format = format_from_path(path);
  FileBytes file(path);
  std::string_view bytes = file.view();
  switch (format) {
    case FileFormat::off:
      return read_off(bytes, path);
    case FileFormat::obj:
      return read_obj(bytes, path);
    case FileFormat::ply:
      return read_ply(bytes, path);
    case FileFormat::stl:
      return read_stl(bytes, path);
  }
  throw Error(path + ": unknown format");
}

std::string io_detail::Pieces::joined() && {
  if (parts.size() == 1) return std::move(parts[0]);
  std::size_t total = 0;
  for (const std::string& part : parts) total += part.size();
  std::string out;
  out.reserve(total);
  for (std::string& part : parts) {
    out += part;
    std::string().swap(part);  // each piece's memory goes as soon as it is copied
  }
  return out;
}

void write_mesh(const Soup& soup, const std::string& path, const WriteOptions& options) {
  FileFormat format = format_from_path(path);
  // Everything is formatted before the file is touched, so a soup the writer refuses
  // leaves an existing file as it was.
  io_detail::Pieces bytes;
  switch (format) {
    case FileFormat::off:
      bytes = io_detail::format_off(soup);
      break;
    case FileFormat::obj:
      bytes = io_detail::format_obj(soup);
      break;
    case FileFormat::ply:
      bytes = io_detail::format_ply(soup, options.binary);
      break;
    case FileFormat::stl:
      bytes = io_detail::format_stl(soup, options.binary);
      break;
  }

  // The temporary file sits next to the target so rename() stays within one file system
  // and replaces the target atomically.
  static std::atomic<unsigned> counter{0};
  std::string temp = path + ".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(counter++);
  int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
  if (fd < 0) throw Error("cannot write " + path + ": " + system_reason(errno));
  auto give_up = [&](int error) {
    ::close(fd);
    ::unlink(temp.c_str());
    throw Error("cannot write " + path + ": " + system_reason(error));
  };
  for (std::string& part : bytes.parts) {
    const char* p = part.data();
    std::size_t left = part.size();
    while (left > 0) {
      ssize_t n = ::write(fd, p, left);
      if (n < 0) {
        if (errno == EINTR) continue;
        give_up(errno);
      }
      p += n;
      left -= static_cast<std::size_t>(n);
    }
    std::string().swap(part);  // written: its memory goes
  }
  if (::fsync(fd) != 0 && errno != EINVAL && errno != EROFS) give_up(errno);
  if (::close(fd) != 0) {
    int error = errno;
    ::unlink(temp.c_str());
    throw Error("cannot write " + path + ": " + system_reason(error));
  }
  if (::rename(temp.c_str(), path.c_str()) != 0) {
    int error = errno;
    ::unlink(temp.c_str());
    throw Error("cannot write " + path + ": " + system_reason(error));
  }
}

}  // namespace hedge
