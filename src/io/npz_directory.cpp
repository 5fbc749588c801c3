// Reading an .npz archive's central directory: the end record (after which a
// comment may stand), the ZIP64 end record and its locator, the directory's
// entries with their ZIP64 extra fields, and each member's local header. Nothing in
// the file is trusted: every offset and size is checked before it is used.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <optional>
#include <string>
#include <vector>

#include "base/excerpt.hpp"
#include "base/text.hpp"
#include "io/npz_archive.hpp"

namespace interpatch::io::internal::npz_io {

namespace {

/// Where the end records say the central directory is.
struct DirectoryPlace {
  std::uint64_t entries = 0, size = 0, offset = 0;
};

class DirectoryReader {
 public:
  DirectoryReader(const Source& src, const std::string& name) : src_(src), name_(name) {}

  std::vector<Entry> read() {
    const DirectoryPlace place = find_directory();
    const std::uint64_t entries = place.entries, dir_size = place.size, dir_offset = place.offset;
    // An exact form has at most seven members: a directory of a megabyte is not one.
    constexpr std::uint64_t max_directory = std::uint64_t{1} << 20;
    if (dir_size > max_directory)
      malformed("a central directory of ", dir_size, " bytes (", entries, " entries) is not that of an exact form (",
                member_list, ")");
    std::vector<unsigned char> dir(static_cast<std::size_t>(dir_size));
    src_.read(reinterpret_cast<char*>(dir.data()), dir.size(), dir_offset);
    std::vector<Entry> found;
    std::size_t p = 0;
    for (std::uint64_t k = 0; k < entries; ++k) found.push_back(entry(dir, p, k, entries));
    if (p != dir.size())
      malformed("the central directory holds ", dir.size() - p, " bytes after its ", entries, " entries");
    for (std::size_t k = 0; k < found.size(); ++k) {
      const Entry& e = found[k];
      const std::string shown = "'" + detail::excerpt(e.name, 60) + "'";
      if (std::find(member_names.begin(), member_names.end(), e.name) == member_names.end())
        malformed("member ", shown, " is not an array of an exact form (", member_list, ")");
      for (std::size_t j = 0; j < k; ++j)
        if (found[j].name == e.name) malformed("member ", shown, " appears twice");
      locate(found[k], dir_offset);
    }
    return found;
  }

 private:
  template <class... A>
  [[noreturn]] void malformed(const A&... parts) const {
    npz_io::malformed(name_, parts...);
  }

  // The end record, and the ZIP64 one when there is one.
  DirectoryPlace find_directory() const {
    const std::uint64_t size = src_.size();
    if (size >= 6) {
      char start[6];
      src_.read(start, 6, 0);
      if (std::memcmp(start, "\x93NUMPY", 6) == 0)
        malformed("a single .npy array, not an .npz archive of the exact form's arrays (", member_list, ")");
    }
    if (size < end_size)
      malformed("not an .npz archive (", size, " bytes, shorter than the 22-byte end record of a ZIP file)");
    // The end record is the last 22 bytes, followed by a comment of at most 64 KiB.
    const auto tail_size = static_cast<std::size_t>(std::min<std::uint64_t>(size, end_size + 0xFFFF));
    std::vector<unsigned char> tail(tail_size);
    src_.read(reinterpret_cast<char*>(tail.data()), tail_size, size - tail_size);
    std::optional<std::size_t> found;
    for (std::size_t p = tail_size - end_size + 1; p-- > 0;)
      if (get_le(&tail[p], 4) == end_signature && p + end_size + get_le(&tail[p + 20], 2) == tail_size) {
        found = p;
        break;
      }
    if (!found) {
      unsigned char start[4] = {};
      src_.read(reinterpret_cast<char*>(start), std::min<std::size_t>(4, size), 0);
      if (get_le(start, 4) == local_signature)
        malformed("truncated ZIP archive: no end-of-central-directory record in its last ", tail_size, " of ", size,
                  " bytes");
      malformed("not an .npz archive: no ZIP end-of-central-directory record in its last ", tail_size, " of ", size,
                " bytes");
    }
    return place(tail.data(), *found, size - tail_size + *found);
  }

  // What the end record at end_at (tail + found in memory) says, or the ZIP64 end
  // record its locator points to.
  DirectoryPlace place(const unsigned char* tail, std::size_t found, std::uint64_t end_at) const {
    const std::uint64_t size = src_.size();
    const unsigned char* end = tail + found;
    if (get_le(end + 4, 2) != 0 || get_le(end + 6, 2) != 0)
      malformed("the archive spans several disks (end record: disk ", get_le(end + 4, 2), ", directory on disk ",
                get_le(end + 6, 2), "); only single-file archives are read");
    std::uint64_t entries = get_le(end + 10, 2), dir_size = get_le(end + 12, 4), dir_offset = get_le(end + 16, 4);
    std::uint64_t records_at = end_at;  // where the end records begin: the directory ends before
    if (found >= locator_size && get_le(end - locator_size, 4) == locator_signature) {
      const unsigned char* loc = end - locator_size;
      const std::uint64_t at = get_le(loc + 8, 8);
      records_at = end_at - locator_size;
      if (at > records_at || records_at - at < end64_size)
        malformed("the ZIP64 end record at offset ", at, " lies outside the ", records_at, " bytes before its locator");
      unsigned char z[end64_size];
      src_.read(reinterpret_cast<char*>(z), end64_size, at);
      if (get_le(z, 4) != end64_signature) malformed("no ZIP64 end record at offset ", at, ", where its locator points");
      if (get_le(z + 16, 4) != 0 || get_le(z + 20, 4) != 0 || get_le(loc + 16, 4) > 1)
        malformed("the archive spans several disks (ZIP64 end record); only single-file archives are read");
      entries = get_le(z + 32, 8);
      dir_size = get_le(z + 40, 8);
      dir_offset = get_le(z + 48, 8);
      records_at = at;
    } else if (entries == escape16 || dir_size == escape32 || dir_offset == escape32) {
      malformed("the end record refers to a ZIP64 end record (", entries, " entries, directory of ", dir_size,
                " bytes at offset ", dir_offset, "), but there is none");
    }
    if (dir_offset > records_at || dir_size > records_at - dir_offset)
      malformed("the central directory (", dir_size, " bytes at offset ", dir_offset, ") runs past the end records at offset ",
                records_at, " (the file has ", size, " bytes)");
    return {entries, dir_size, dir_offset};
  }

  // Entry k + 1 of `entries`, at byte p of the directory `dir`; p moves past it.
  Entry entry(const std::vector<unsigned char>& dir, std::size_t& p, std::uint64_t k, std::uint64_t entries) const {
    const std::size_t dir_size = dir.size();
    if (dir.size() - p < central_size || get_le(&dir[p], 4) != central_signature)
      malformed("the central directory (", dir_size, " bytes) ends or is damaged at its byte ", p, ", in entry ", k + 1,
                " of ", entries);
    const unsigned char* h = &dir[p];
    const std::size_t name_len = get_le(h + 28, 2), extra_len = get_le(h + 30, 2), comment_len = get_le(h + 32, 2);
    if (dir.size() - p - central_size < name_len + extra_len + comment_len)
      malformed("entry ", k + 1, " of the central directory runs past its end (", dir_size, " bytes)");
    Entry e;
    e.name.assign(reinterpret_cast<const char*>(h + central_size), name_len);
    const std::string shown = "'" + detail::excerpt(e.name, 60) + "'";
    if (get_le(h + 8, 2) & 1u) malformed("member ", shown, " is encrypted; only plain stored members are read");
    if (const std::uint64_t method = get_le(h + 10, 2); method != 0)
      malformed("member ", shown, " is compressed (method ", method, method == 8 ? ", deflate" : "",
                "); only stored members are read: write the archive with numpy.savez, not numpy.savez_compressed");
    e.crc = static_cast<std::uint32_t>(get_le(h + 16, 4));
    std::uint64_t compressed = get_le(h + 20, 4), size_field = get_le(h + 24, 4);
    e.local = get_le(h + 42, 4);
    // The ZIP64 extra field holds, in this order, the fields whose places hold the escape.
    const unsigned char* extra = h + central_size + name_len;
    for (std::size_t q = 0; q + 4 <= extra_len;) {
      const std::uint64_t id = get_le(extra + q, 2), len = get_le(extra + q + 2, 2);
      if (q + 4 + len > extra_len) malformed("member ", shown, ": extra field ", id, " runs past the extra data");
      if (id == zip64_extra_id) {
        std::size_t r = q + 4;
        for (std::uint64_t* field : {&size_field, &compressed, &e.local}) {
          if (*field != escape32) continue;
          if (r + 8 > q + 4 + len) malformed("member ", shown, ": the ZIP64 extra field lacks a size or an offset");
          *field = get_le(extra + r, 8);
          r += 8;
        }
      }
      q += 4 + len;
    }
    for (const std::uint64_t v : {size_field, compressed, e.local})
      if (v == escape32) malformed("member ", shown, " refers to a ZIP64 extra field it does not have");
    if (compressed != size_field)
      malformed("stored member ", shown, " has ", compressed, " bytes in the archive but a size of ", size_field);
    e.size = size_field;
    p += central_size + name_len + extra_len + comment_len;
    return e;
  }

  // The member's local header, and where its bytes are; all before the directory.
  void locate(Entry& e, std::uint64_t dir_offset) const {
    if (e.local > dir_offset || dir_offset - e.local < local_size)
      malformed("member '", e.name, "': its local header at offset ", e.local, " is not before the central directory at ",
                dir_offset);
    unsigned char h[local_size];
    src_.read(reinterpret_cast<char*>(h), local_size, e.local);
    if (get_le(h, 4) != local_signature)
      malformed("member '", e.name, "': no local header at offset ", e.local, " (bad signature)");
    if (get_le(h + 8, 2) != 0) malformed("member '", e.name, "' is compressed in its local header; only stored members are read");
    const std::uint64_t name_len = get_le(h + 26, 2), extra_len = get_le(h + 28, 2);
    const std::uint64_t room = dir_offset - e.local - local_size;
    if (name_len + extra_len > room || e.size > room - name_len - extra_len)
      malformed("member '", e.name, "' of ", e.size, " bytes at offset ", e.local + local_size + name_len + extra_len,
                " runs past the central directory at offset ", dir_offset, " (the file has ", src_.size(), " bytes)");
    std::string local_name(name_len, '\0');
    src_.read(local_name.data(), local_name.size(), e.local + local_size);
    if (local_name != e.name)
      malformed("member '", e.name, "': its local header names it '", detail::excerpt(local_name, 60), "'");
    e.data = e.local + local_size + name_len + extra_len;
  }

  const Source& src_;
  const std::string& name_;
};

}  // namespace

std::vector<Entry> read_directory(const Source& src, const std::string& name) { return DirectoryReader(src, name).read(); }

}  // namespace interpatch::io::internal::npz_io
