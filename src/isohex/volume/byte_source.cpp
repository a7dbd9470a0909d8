#include "isohex/volume/byte_source.hpp"

#include "isohex/error.hpp"

#include <fmt/format.h>
#include <zlib.h>

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cstring>
#include <system_error>

namespace isohex::volume_detail {

namespace fs = std::filesystem;

namespace {
constexpr std::size_t kInflateBuffer = std::size_t{1} << 16;
}

bool ByteSource::skip(std::size_t n) {
  unsigned char buf[4096];
  while (n > 0) {
    const std::size_t want = std::min(n, sizeof buf);
    const std::size_t got = read(buf, want);
    n -= got;
    if (got < want) return n == 0;
  }
  return true;
}

std::size_t read_full(ByteSource& source, unsigned char* out, std::size_t n) {
  std::size_t done = 0;
  while (done < n) {
    const std::size_t got = source.read(out + done, n - done);
    if (got == 0) break;
    done += got;
  }
  return done;
}

std::size_t size_of_file(const fs::path& file) {
  std::error_code ec;
  if (!fs::exists(file, ec)) throw Error(fmt::format("{}: cannot open: no such file", file.string()));
  if (fs::is_directory(file, ec)) throw Error(fmt::format("{}: cannot read: it is a folder", file.string()));
  const auto size = fs::file_size(file, ec);
  if (ec) throw Error(fmt::format("{}: cannot read: {}", file.string(), ec.message()));
  return static_cast<std::size_t>(size);
}

FileSource::FileSource(const fs::path& file, std::size_t offset) : file_(file), size_(size_of_file(file)) {
  fp_.reset(std::fopen(file.c_str(), "rb"));
  if (!fp_) throw Error(fmt::format("{}: cannot open: {}", file.string(), std::strerror(errno)));
  if (offset > size_)
    throw Error(
        fmt::format("{}: data should start at byte {}, but the file has only {} bytes", file.string(), offset, size_));
  if (offset > 0 && fseeko(fp_.get(), static_cast<off_t>(offset), SEEK_SET) != 0)
    throw Error(fmt::format("{}: cannot seek to byte {}: {}", file.string(), offset, std::strerror(errno)));
  pos_ = offset;
}

std::size_t FileSource::read(unsigned char* out, std::size_t n) {
  const std::size_t got = std::fread(out, 1, n, fp_.get());
  if (got < n && std::ferror(fp_.get()))
    throw Error(fmt::format("{}: read error at byte {}: {}", file_.string(), pos_ + got, std::strerror(errno)));
  pos_ += got;
  return got;
}

std::size_t MemorySource::read(unsigned char* out, std::size_t n) {
  const std::size_t got = std::min(n, bytes_.size() - pos_);
  std::memcpy(out, bytes_.data() + pos_, got);
  pos_ += got;
  return got;
}

InflateSource::InflateSource(ByteSource& input, fs::path file, std::string what)
    : input_(input),
      file_(std::move(file)),
      what_(std::move(what)),
      zs_(std::make_unique<z_stream>()),
      buffer_(std::make_unique<unsigned char[]>(kInflateBuffer)) {
  // 15 + 32: the largest window, with the zlib or gzip wrapper detected automatically.
  if (inflateInit2(zs_.get(), 15 + 32) != Z_OK) fail("zlib initialisation failed");
}

InflateSource::~InflateSource() { inflateEnd(zs_.get()); }

void InflateSource::fail(std::string_view what) const {
  throw Error(fmt::format("{}: {}: {}", file_.string(), what_, what));
}

bool InflateSource::refill() {
  if (input_ended_) return false;
  const std::size_t got = input_.read(buffer_.get(), kInflateBuffer);
  if (got == 0) {
    input_ended_ = true;
    return false;
  }
  zs_->next_in = buffer_.get();
  zs_->avail_in = static_cast<uInt>(got);
  consumed_ += got;
  return true;
}

std::size_t InflateSource::read(unsigned char* out, std::size_t n) {
  std::size_t done = 0;
  while (done < n && !ended_) {
    if (zs_->avail_in == 0 && !refill())
      fail(fmt::format("truncated: the compressed stream ends after {} bytes, before its end marker", consumed_));
    const std::size_t want = std::min<std::size_t>(n - done, UINT_MAX);
    zs_->next_out = out + done;
    zs_->avail_out = static_cast<uInt>(want);
    const int r = inflate(zs_.get(), Z_NO_FLUSH);
    done += want - zs_->avail_out;
    if (r == Z_STREAM_END) {
      // Another gzip member may follow (gzip concatenates them); anything else is ignored.
      if (zs_->avail_in == 0) refill();
      if (zs_->avail_in >= 2 && zs_->next_in[0] == 0x1f && zs_->next_in[1] == 0x8b) {
        if (inflateReset(zs_.get()) != Z_OK) fail("zlib reset failed");
      } else {
        ended_ = true;
      }
    } else if (r == Z_DATA_ERROR || r == Z_NEED_DICT) {
      fail(fmt::format("corrupt compressed data ({})", zs_->msg ? zs_->msg : "invalid stream"));
    } else if (r == Z_MEM_ERROR) {
      fail("out of memory while inflating");
    } else if (r != Z_OK && r != Z_BUF_ERROR) {
      fail(fmt::format("zlib error {}", r));
    }
  }
  return done;
}

std::string read_prefix(const fs::path& file, std::size_t n) {
  FileSource src(file, 0);
  std::string out(std::min(n, src.remaining()), '\0');
  out.resize(read_full(src, reinterpret_cast<unsigned char*>(out.data()), out.size()));
  return out;
}

}  // namespace isohex::volume_detail
