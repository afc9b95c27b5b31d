#include "rms/base/config_settings.h"

#include <sstream>
#include <toml++/toml.h>
#include <utility>

#include "rms/base/check.h"
#include "rms/base/toml_reader.h"

#include "config_table.h"

namespace rms {

namespace {

// The kind of a TOML value, as a person reads it; int and float are both "a number".
const char* KindName(const toml::node& n) {
  if (n.is_number()) return "a number";
  if (n.is_boolean()) return "true or false";
  if (n.is_string()) return "a string";
  if (n.is_array()) return "an array";
  if (n.is_table()) return "a table";
  return "a date or time";
}

// Where a dotted key ("a.b[2].c") lives: its table (or array) and its name
// (or index) there.
struct Slot {
  toml::node* node = nullptr;
  toml::table* table = nullptr;  // the key's table, or
  toml::array* array = nullptr;  // ... the array it is an element of
  std::string name;
  std::size_t index = 0;
};

// The slot a dotted key names; node nullptr with *why said.
Slot Find(toml::table* root, const std::string& key, std::string* why) {
  Slot slot;
  toml::node* at = root;
  std::istringstream parts(key);
  std::string part;
  while (std::getline(parts, part, '.')) {
    std::string name = part;
    long index = -1;
    if (const auto lb = part.find('['); lb != std::string::npos && part.back() == ']') {
      name = part.substr(0, lb);
      const std::string digits = part.substr(lb + 1, part.size() - lb - 2);
      const bool number = !digits.empty() && digits.size() <= 6 &&
                          digits.find_first_not_of("0123456789") == std::string::npos;
      index = number ? std::stol(digits) : -2;
      if (index < 0) {
        *why = "'" + part + "' has no index a number";
        return {};
      }
    }
    toml::table* t = at ? at->as_table() : nullptr;
    toml::node* next = (t && !name.empty()) ? t->get(name) : nullptr;
    if (!next) {
      *why = "the configuration has no key '" + name + "' there";
      return {};
    }
    slot = Slot{next, t, nullptr, name, 0};
    if (index >= 0) {
      toml::array* a = next->as_array();
      if (!a || index >= static_cast<long>(a->size())) {
        *why = "'" + name + "' has no element " + std::to_string(index);
        return {};
      }
      next = a->get(static_cast<std::size_t>(index));
      slot = Slot{next, nullptr, a, name, static_cast<std::size_t>(index)};
    }
    at = next;
  }
  return slot;
}

// Puts v where the slot is.
template <typename V>
void Put(const Slot& slot, V&& v) {
  if (slot.table) {
    slot.table->insert_or_assign(slot.name, std::forward<V>(v));
  } else {
    slot.array->replace(slot.array->cbegin() + static_cast<std::ptrdiff_t>(slot.index),
                        std::forward<V>(v));
  }
}

}  // namespace

ConfigSetting ParseConfigSetting(const std::string& text) {
  const auto eq = text.find('=');
  if (eq == std::string::npos || eq == 0 || eq + 1 == text.size()) {
    throw InputError("--set '" + text + "': must be KEY=VALUE, e.g. dcp.tpob_ft=0.4");
  }
  return {text.substr(0, eq), text.substr(eq + 1)};
}

namespace {

// Each setting put into root in order (ApplyConfigSettings's rules).
void SetKeys(toml::table& root, const std::string& source,
             const std::vector<ConfigSetting>& settings) {
  for (const ConfigSetting& s : settings) {
    std::string why;
    const Slot slot = Find(&root, s.key, &why);
    const toml::node* node = slot.node;
    if (!node) {
      std::string what = "--set " + s.key;
      what.append(": ").append(why).append(" (").append(source).append(")");
      throw InputError(what);
    }
    if (node->is_table()) {
      throw InputError("--set " + s.key + ": is a table; set one of its keys (" + source + ")");
    }
    toml::table parsed;
    try {
      parsed = toml::parse(std::string_view("v = " + s.value), std::string_view("--set"));
    } catch (const toml::parse_error& e) {
      throw InputError("--set " + s.key + "=" + s.value + ": '" + s.value + "' is no TOML value (" +
                       std::string(e.description()) + ")");
    }
    const toml::node& value = *parsed.get("v");
    if (std::string(KindName(value)) != KindName(*node)) {
      throw InputError("--set " + s.key + "=" + s.value + ": the key is " + KindName(*node) +
                       ", the value " + KindName(value));
    }
    // A number keeps the key's own kind: 1 for a float key is 1.0.
    if (node->is_floating_point() && value.is_integer()) {
      Put(slot, static_cast<double>(value.as_integer()->get()));
    } else {
      value.visit([&](auto&& v) { Put(slot, v); });
    }
  }
}

}  // namespace

std::string ApplyConfigSettings(std::string_view toml_text, const std::string& source,
                                const std::vector<ConfigSetting>& settings) {
  toml::table root = ParseToml(toml_text, source);
  SetKeys(root, source, settings);
  std::ostringstream os;
  os << root << "\n";
  return os.str();
}

struct ConfigDesigns::Parsed {
  toml::table root;
  std::string source;
};

ConfigDesigns::ConfigDesigns(std::string_view toml_text, std::string source)
    // (A braced list is evaluated in order: the text is parsed before the
    // source moves.)
    : parsed_(
          std::make_unique<const Parsed>(Parsed{ParseToml(toml_text, source), std::move(source)})) {
}

ConfigDesigns::~ConfigDesigns() = default;

LabConfig ConfigDesigns::With(const std::vector<ConfigSetting>& settings,
                              const std::string& name) const {
  toml::table root = parsed_->root;
  SetKeys(root, parsed_->source, settings);
  return internal::ConfigFromTable(&root, name);
}

}  // namespace rms
