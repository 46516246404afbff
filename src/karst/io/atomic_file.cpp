#include "karst/io/atomic_file.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace karst {

namespace {

/// The failure, with the operating system's reason (disk full, permission denied, ...).
[[noreturn]] void fail(const char* what, const std::filesystem::path& path, int error) {
    throw std::runtime_error(
        fmt::format("cannot {} '{}': {}", what, path.string(), std::strerror(error)));
}

}  // namespace

void write_file_atomically(const std::filesystem::path& path, std::string_view bytes) {
    std::filesystem::path tmp = path;
    tmp += ".tmp";
    const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd < 0) fail("create", tmp, errno);
    auto give_up = [&](const char* what) {
        const int error = errno;
        ::close(fd);
        ::unlink(tmp.c_str());
        fail(what, tmp, error);
    };
    for (size_t done = 0; done < bytes.size();) {
        const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) give_up("write");
        done += size_t(n);
    }
    // On disk before it takes the real name: after a power cut the file is old or new, not empty.
    if (::fsync(fd) != 0) give_up("flush");
    if (::close(fd) != 0) {
        const int error = errno;
        ::unlink(tmp.c_str());
        fail("close", tmp, error);
    }
    if (::rename(tmp.c_str(), path.c_str()) != 0) {
        const int error = errno;
        ::unlink(tmp.c_str());
        fail("rename over", path, error);
    }
}

}  // namespace karst
