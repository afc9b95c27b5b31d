#pragma once
// Strict reading of TOML configuration files (config/rmslab.toml,
// config/bindings.toml): every key asked for must be present and
// well-formed, and Finish() refuses keys nobody asked for. Errors are
// rms::InputError naming the file, the key and the reason:
//   "config/rmslab.toml: key 'arm.upper_boom_ft': must be > 0, got -3"
#include <Eigen/Core>
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <string_view>
#include <toml++/toml.h>
#include <utility>
#include <vector>

#include "rms/base/check.h"
#include "rms/base/folder_file.h"

namespace rms {

inline std::string FormatNumber(double v) {
  std::ostringstream os;
  os.precision(10);
  os << v;
  return os.str();
}

// Reads one TOML table strictly: every key it is asked for must be present
// and well-formed; Finish() refuses keys nobody asked for.
class TomlReader {
 public:
  // doc: the page that documents the keys, named in the errors.
  TomlReader(const toml::table* table, std::string path, const std::string* source,
             std::string doc = "docs/config.md")
      : table_(table), path_(std::move(path)), source_(source), doc_(std::move(doc)) {}

  [[noreturn]] void Fail(std::string_view key, const std::string& reason) const {
    throw InputError(*source_ + ": key '" + Key(key) + "': " + reason);
  }
  std::string Key(std::string_view key) const {
    return path_.empty() ? std::string(key) : path_ + "." + std::string(key);
  }

  const toml::node* Get(std::string_view key) {
    used_.insert(std::string(key));
    const toml::node* n = table_->get(key);
    if (n == nullptr) {
      // A key present under a near spelling is named: the likely typo.
      std::string near;
      for (auto&& [k, v] : *table_) {
        if (!used_.count(std::string(k.str())) && EditDistance(k.str(), key) <= 2)
          near = std::string(k.str());
      }
      Fail(key, "missing (every key is required; see " + doc_ + ")" +
                    (near.empty() ? "" : "; the file has '" + Key(near) + "': misspelt?"));
    }
    return n;
  }

  // Levenshtein distance, for naming a misspelt key.
  static std::size_t EditDistance(std::string_view a, std::string_view b) {
    std::vector<std::size_t> row(b.size() + 1);
    for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
    for (std::size_t i = 1; i <= a.size(); ++i) {
      std::size_t diag = row[0];
      row[0] = i;
      for (std::size_t j = 1; j <= b.size(); ++j) {
        const std::size_t up = row[j];
        row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (a[i - 1] == b[j - 1] ? 0 : 1)});
        diag = up;
      }
    }
    return row[b.size()];
  }

  double Number(std::string_view key, double lo, double hi, bool open_lo = false) {
    const toml::node* n = Get(key);
    std::optional<double> v = n->value<double>();
    if (!v || !(n->is_integer() || n->is_floating_point())) Fail(key, "must be a number");
    CheckRange(key, *v, lo, hi, open_lo);
    return *v;
  }

  void CheckRange(std::string_view key, double v, double lo, double hi, bool open_lo) const {
    if (!std::isfinite(v)) Fail(key, "must be finite, got " + FormatNumber(v));
    if (open_lo ? !(v > lo) : !(v >= lo)) {
      Fail(key, "must be " + std::string(open_lo ? "> " : ">= ") + FormatNumber(lo) + ", got " +
                    FormatNumber(v));
    }
    if (!(v <= hi)) Fail(key, "must be <= " + FormatNumber(hi) + ", got " + FormatNumber(v));
  }

  double Positive(std::string_view key, double hi = 1e4) { return Number(key, 0.0, hi, true); }

  std::vector<double> Numbers(std::string_view key, std::size_t count, double lo, double hi) {
    const toml::node* n = Get(key);
    const toml::array* a = n->as_array();
    if (a == nullptr || a->size() != count) {
      Fail(key, "must be an array of " + std::to_string(count) + " numbers");
    }
    std::vector<double> out;
    for (const toml::node& e : *a) {
      std::optional<double> v = e.value<double>();
      if (!v || !(e.is_integer() || e.is_floating_point())) {
        Fail(key, "must be an array of " + std::to_string(count) + " numbers");
      }
      CheckRange(key, *v, lo, hi, false);
      out.push_back(*v);
    }
    return out;
  }

  Eigen::Vector3d Vec3(std::string_view key, double limit = 1e4) {
    std::vector<double> v = Numbers(key, 3, -limit, limit);
    return {v[0], v[1], v[2]};
  }

  std::pair<double, double> Range(std::string_view key, double lo, double hi) {
    std::vector<double> v = Numbers(key, 2, lo, hi);
    if (!(v[0] < v[1])) Fail(key, "must be [low, high] with low < high");
    return {v[0], v[1]};
  }

  std::string String(std::string_view key) {
    const toml::node* n = Get(key);
    std::optional<std::string> v = n->value<std::string>();
    if (!v || !n->is_string()) Fail(key, "must be a string");
    return *v;
  }

  TomlReader Sub(std::string_view key) {
    const toml::node* n = Get(key);
    const toml::table* t = n->as_table();
    if (t == nullptr) Fail(key, "must be a table");
    return TomlReader(t, Key(key), source_, doc_);
  }

  const toml::array* Array(std::string_view key) {
    const toml::node* n = Get(key);
    const toml::array* a = n->as_array();
    if (a == nullptr) Fail(key, "must be an array of tables ([[" + Key(key) + "]])");
    return a;
  }

  // A rotation from two unit axes given in R (y and z); x = y cross z.
  Eigen::Matrix3d Rotation(std::string_view y_key, std::string_view z_key) {
    Eigen::Vector3d y = Vec3(y_key), z = Vec3(z_key);
    if (std::abs(y.norm() - 1.0) > 1e-6) Fail(y_key, "must be a unit vector");
    if (std::abs(z.norm() - 1.0) > 1e-6) Fail(z_key, "must be a unit vector");
    if (std::abs(y.dot(z)) > 1e-6) Fail(z_key, "must be perpendicular to " + Key(y_key));
    // Within 1e-6 of a rotation: made exactly orthonormal (y kept in its
    // direction), so the models built on it have exactly planar faces.
    y.normalize();
    z = (z - z.dot(y) * y).normalized();
    Eigen::Matrix3d r;
    r.col(0) = y.cross(z);
    r.col(1) = y;
    r.col(2) = z;
    return r;
  }

  void Finish() const {
    for (auto&& [k, v] : *table_) {
      if (!used_.count(std::string(k.str()))) {
        throw InputError(*source_ + ": key '" + Key(k.str()) + "': unknown key (misspelt? see " +
                         doc_ + ")");
      }
    }
  }

  const std::string& path() const { return path_; }
  const std::string& source() const { return *source_; }
  const toml::table& table() const { return *table_; }
  bool Has(std::string_view key) const { return table_->contains(key); }
  // Marks a key as read (for free-form tables read by iterating table()).
  void Use(std::string_view key) { used_.insert(std::string(key)); }

 private:
  const toml::table* table_;
  std::string path_;
  const std::string* source_;
  std::string doc_;
  std::set<std::string> used_;
};

// The largest text file read (a configuration, lab file or summary is
// kilobytes; /dev/zero, or a log given by mistake, is refused, not read
// into memory without end).
inline constexpr std::size_t kMaxTextFileBytes = std::size_t{64} << 20;

// A whole text file the user named (links followed, a FIFO read to its
// end; rms/base/folder_file.h): an InputError "cannot read WHAT 'PATH': WHY"
// when it can't be read, is a folder or a device, or is larger than
// kMaxTextFileBytes. A file of a session folder: ReadRegularFile with
// Links::kRefuse.
inline std::string ReadTextFile(const std::string& path, const std::string& what) {
  return ReadRegularFile(path, what, kMaxTextFileBytes, Links::kFollow);
}

// Parses TOML text; a syntax error is an InputError "SOURCE:LINE:COLUMN:
// TOML syntax error: ...".
inline toml::table ParseToml(std::string_view text, const std::string& source) {
  try {
    return toml::parse(text, source);
  } catch (const toml::parse_error& e) {
    std::ostringstream os;
    os << source << ":" << e.source().begin.line << ":" << e.source().begin.column
       << ": TOML syntax error: " << e.description();
    throw InputError(os.str());
  }
}

}  // namespace rms
