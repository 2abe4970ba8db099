#include "coloc/ndt/pcd_file.hpp"

// PCD is read by coloc's own parser: PCL's reader crashes on some malformed files (seen on a file
// with no header), and a map loader must survive whatever is on the disk.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <sstream>

#include "coloc/core/error.hpp"

namespace coloc::ndt {

namespace {

struct Field {
  std::string name;
  int size = 4;
  char type = 'F';
  int count = 1;
  std::size_t offset = 0;  ///< within a point record
};

struct Header {
  std::vector<Field> fields;
  std::size_t width = 0, height = 1, points = 0;
  std::string data;
  std::size_t point_step = 0;
  std::size_t data_start = 0;  ///< byte offset of the data section
};

[[noreturn]] void fail(const std::string& path, const std::string& why) { throw Error(path + ": " + why); }

std::size_t parseCount(const std::string& path, const std::string& key, const std::string& text) {
  try {
    std::size_t used = 0;
    const long long v = std::stoll(text, &used);
    if (used != text.size() || v < 0) throw std::invalid_argument("");
    return static_cast<std::size_t>(v);
  } catch (const std::exception&) {
    fail(path, "header " + key + " '" + text + "' is not a non-negative integer");
  }
}

Header parseHeader(const std::string& path, const std::string& bytes) {
  Header h;
  std::size_t pos = 0;
  std::vector<std::string> sizes, types, counts;
  while (h.data.empty()) {
    if (pos >= bytes.size()) fail(path, "not a readable PCD file (corrupt or truncated header or data): no DATA line");
    std::size_t end = bytes.find('\n', pos);
    if (end == std::string::npos) end = bytes.size();
    std::string line = bytes.substr(pos, end - pos);
    pos = end + 1;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty() || line[0] == '#') continue;
    std::istringstream in(line);
    std::string key, word;
    in >> key;
    std::vector<std::string> words;
    while (in >> word) words.push_back(word);
    if (key == "VERSION" || key == "VIEWPOINT") continue;
    if (key == "FIELDS") {
      for (const auto& w : words) h.fields.push_back({w});
    } else if (key == "SIZE") {
      sizes = words;
    } else if (key == "TYPE") {
      types = words;
    } else if (key == "COUNT") {
      counts = words;
    } else if (key == "WIDTH" && words.size() == 1) {
      h.width = parseCount(path, key, words[0]);
    } else if (key == "HEIGHT" && words.size() == 1) {
      h.height = parseCount(path, key, words[0]);
    } else if (key == "POINTS" && words.size() == 1) {
      h.points = parseCount(path, key, words[0]);
    } else if (key == "DATA" && words.size() == 1) {
      h.data = words[0];
    } else {
      fail(path, "not a readable PCD file (corrupt or truncated header or data): unexpected header line '" + line.substr(0, 60) + "'");
    }
  }
  h.data_start = pos;
  if (h.fields.empty() || sizes.size() != h.fields.size() || types.size() != h.fields.size() ||
      (!counts.empty() && counts.size() != h.fields.size()))
    fail(path, "not a readable PCD file (corrupt or truncated header or data): FIELDS, SIZE, TYPE and COUNT disagree");
  for (std::size_t i = 0; i < h.fields.size(); ++i) {
    Field& f = h.fields[i];
    f.size = static_cast<int>(parseCount(path, "SIZE", sizes[i]));
    if (types[i].size() != 1 || std::string("IUF").find(types[i][0]) == std::string::npos) fail(path, "header TYPE '" + types[i] + "' is not I, U or F");
    f.type = types[i][0];
    f.count = counts.empty() ? 1 : static_cast<int>(parseCount(path, "COUNT", counts[i]));
    if (f.size != 1 && f.size != 2 && f.size != 4 && f.size != 8) fail(path, "header SIZE " + sizes[i] + " is not 1, 2, 4 or 8");
    if (f.count < 1 || f.count > 1'000'000) fail(path, "header COUNT " + std::to_string(f.count) + " is out of range");
    f.offset = h.point_step;
    h.point_step += static_cast<std::size_t>(f.size) * static_cast<std::size_t>(f.count);
  }
  if (h.height != 0 && h.width > std::numeric_limits<std::size_t>::max() / h.height) fail(path, "header WIDTH x HEIGHT is out of range");
  if (h.points == 0) h.points = h.width * h.height;
  if (h.points != h.width * h.height) fail(path, "header POINTS differs from WIDTH x HEIGHT");
  return h;
}

double readBinary(const std::uint8_t* at, const Field& f) {
  switch (f.type) {
    case 'F':
      if (f.size == 4) { float v; std::memcpy(&v, at, 4); return v; }
      if (f.size == 8) { double v; std::memcpy(&v, at, 8); return v; }
      break;
    case 'I':
      if (f.size == 1) { std::int8_t v; std::memcpy(&v, at, 1); return v; }
      if (f.size == 2) { std::int16_t v; std::memcpy(&v, at, 2); return v; }
      if (f.size == 4) { std::int32_t v; std::memcpy(&v, at, 4); return v; }
      if (f.size == 8) { std::int64_t v; std::memcpy(&v, at, 8); return static_cast<double>(v); }
      break;
    case 'U':
      if (f.size == 1) return *at;
      if (f.size == 2) { std::uint16_t v; std::memcpy(&v, at, 2); return v; }
      if (f.size == 4) { std::uint32_t v; std::memcpy(&v, at, 4); return v; }
      if (f.size == 8) { std::uint64_t v; std::memcpy(&v, at, 8); return static_cast<double>(v); }
      break;
  }
  return std::nan("");
}

// LZF (liblzf's format, which PCL's binary_compressed uses), with every read and back-reference checked.
std::vector<std::uint8_t> lzfDecompress(const std::string& path, const std::uint8_t* in, std::size_t in_size, std::size_t out_size) {
  std::vector<std::uint8_t> out(out_size);
  std::size_t ip = 0, op = 0;
  const auto corrupt = [&] { fail(path, "not a readable PCD file (corrupt or truncated header or data): compressed data is corrupt"); };
  while (ip < in_size) {
    const unsigned ctrl = in[ip++];
    if (ctrl < 32) {  // a literal run of ctrl + 1 bytes
      const std::size_t n = ctrl + 1;
      if (ip + n > in_size || op + n > out_size) corrupt();
      std::memcpy(&out[op], &in[ip], n);
      ip += n;
      op += n;
    } else {  // a back-reference
      std::size_t len = ctrl >> 5;
      if (len == 7) {
        if (ip >= in_size) corrupt();
        len += in[ip++];
      }
      len += 2;
      if (ip >= in_size) corrupt();
      const std::size_t distance = ((ctrl & 0x1fu) << 8) + in[ip++] + 1;
      if (distance > op || op + len > out_size) corrupt();
      for (std::size_t k = 0; k < len; ++k, ++op) out[op] = out[op - distance];  // may overlap: byte by byte
    }
  }
  if (op != out_size) corrupt();
  return out;
}

}  // namespace

PointCloud loadPcd(const std::string& path, PcdLoadReport* report) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw Error(path + ": no such PCD file");
  std::ifstream file(path, std::ios::binary);
  if (!file) throw Error(path + ": cannot open the PCD file");
  const std::string bytes((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  if (bytes.empty()) throw Error(path + ": the PCD file is empty");
  const Header h = parseHeader(path, bytes);
  auto field = [&](std::initializer_list<const char*> names) -> const Field* {
    for (const char* n : names)
      for (const Field& f : h.fields)
        if (f.name == n) return &f;
    return nullptr;
  };
  const Field* fx = field({"x"});
  const Field* fy = field({"y"});
  const Field* fz = field({"z"});
  if (!fx || !fy || !fz) fail(path, "the PCD file has no x, y and z fields");
  const Field* ft = field({"time", "t", "timestamp"});
  const std::size_t n = h.points;
  // Values of field f for point i, whatever the layout.
  std::vector<double> values[4];
  const Field* wanted[4] = {fx, fy, fz, ft};
  const std::size_t available = bytes.size() - std::min(bytes.size(), h.data_start);
  // The header's count is a claim: a point takes at least a byte, so no more than the data could hold
  // is reserved up front (the data's own checks below say what is missing).
  for (auto& v : values) v.reserve(std::min(n, available));
  const std::uint8_t* data = reinterpret_cast<const std::uint8_t*>(bytes.data()) + h.data_start;
  const std::string truncated = "not a readable PCD file (corrupt or truncated header or data): ";
  if (h.data == "ascii") {
    // One value per element, fields in header order: the column of each wanted field's first element.
    std::size_t column[4] = {0, 0, 0, 0};
    for (int k = 0; k < 4; ++k)
      for (const Field& f : h.fields) {
        if (&f == wanted[k]) break;
        column[k] += static_cast<std::size_t>(f.count);
      }
    std::istringstream in(bytes.substr(std::min(bytes.size(), h.data_start)));  // a header may end the file
    std::string line;
    std::size_t read = 0;
    while (read < n && std::getline(in, line)) {
      if (line.empty() || line == "\r") continue;
      std::istringstream words(line);
      std::vector<double> row;
      std::string w;
      while (words >> w) {
        char* end = nullptr;
        const double v = std::strtod(w.c_str(), &end);
        row.push_back(end && *end == '\0' ? v : std::nan(""));  // unparsable counts as not finite
      }
      for (int k = 0; k < 4; ++k) {
        if (!wanted[k]) continue;
        if (column[k] >= row.size()) fail(path, truncated + "ascii line " + std::to_string(read + 1) + " has too few values");
        values[k].push_back(row[column[k]]);
      }
      ++read;
    }
    if (read < n) fail(path, truncated + "ascii data ends after " + std::to_string(read) + " of " + std::to_string(n) + " points");
  } else if (h.data == "binary") {
    if (h.point_step == 0 || n > available / h.point_step) fail(path, truncated + "binary data is shorter than its header says");
    for (std::size_t i = 0; i < n; ++i)
      for (int k = 0; k < 4; ++k)
        if (wanted[k]) values[k].push_back(readBinary(data + i * h.point_step + wanted[k]->offset, *wanted[k]));
  } else if (h.data == "binary_compressed") {
    if (available < 8) fail(path, truncated + "compressed data has no size words");
    std::uint32_t compressed = 0, uncompressed = 0;
    std::memcpy(&compressed, data, 4);
    std::memcpy(&uncompressed, data + 4, 4);
    if (compressed > available - 8) fail(path, truncated + "compressed data is shorter than its size word says");
    if (h.point_step == 0 || n > std::numeric_limits<std::size_t>::max() / h.point_step || uncompressed != n * h.point_step)
      fail(path, truncated + "uncompressed size disagrees with the header");
    const std::vector<std::uint8_t> raw = lzfDecompress(path, data + 8, compressed, uncompressed);
    // Field-major layout: all values of the first field, then all of the second, ...
    for (int k = 0; k < 4; ++k) {
      if (!wanted[k]) continue;
      const std::size_t element = static_cast<std::size_t>(wanted[k]->size) * static_cast<std::size_t>(wanted[k]->count);
      const std::size_t base = wanted[k]->offset * n;
      for (std::size_t i = 0; i < n; ++i) values[k].push_back(readBinary(raw.data() + base + i * element, *wanted[k]));
    }
  } else {
    fail(path, "DATA '" + h.data + "' is not ascii, binary or binary_compressed");
  }
  PointCloud cloud;
  cloud.points.reserve(n);
  if (ft) cloud.times.reserve(n);
  std::size_t dropped = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double x = values[0][i], y = values[1][i], z = values[2][i];
    if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z)) {
      ++dropped;
      continue;
    }
    cloud.points.emplace_back(static_cast<float>(x), static_cast<float>(y), static_cast<float>(z));
    if (ft) cloud.times.push_back(static_cast<float>(values[3][i]));
  }
  if (report) *report = {n, dropped};
  if (cloud.empty())
    throw Error(path + ": the PCD file holds no finite point (" + std::to_string(n) + " points, " + std::to_string(dropped) +
                " with NaN or infinite coordinates)");
  return cloud;
}

void savePcd(const std::string& path, const PointCloud& cloud) {
  if (cloud.empty()) throw Error(path + ": refusing to write an empty PCD file");
  std::ofstream out(path, std::ios::binary);
  if (!out) throw Error(path + ": cannot write the PCD file");
  const bool times = cloud.hasTimes();
  out << "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS x y z" << (times ? " time" : "") << "\nSIZE 4 4 4"
      << (times ? " 4" : "") << "\nTYPE F F F" << (times ? " F" : "") << "\nCOUNT 1 1 1" << (times ? " 1" : "") << "\nWIDTH "
      << cloud.size() << "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " << cloud.size() << "\nDATA binary\n";
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    out.write(reinterpret_cast<const char*>(cloud.points[i].data()), 12);
    if (times) out.write(reinterpret_cast<const char*>(&cloud.times[i]), 4);
  }
  if (!out) throw Error(path + ": write failed");
}

}  // namespace coloc::ndt
