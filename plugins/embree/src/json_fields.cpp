#include "json_fields.h"

#include <cmath>
#include <limits>
#include <utility>

namespace dcm::embree {

namespace {
/// A JSON number that fits a float (finite, |v| <= FLT_MAX).
bool AsFiniteFloat(const Json& e, float* out) {
  if (!e.is_number()) return false;
  const double d = e.get<double>();
  if (!std::isfinite(d) || std::fabs(d) > double(std::numeric_limits<float>::max())) return false;
  *out = float(d);
  return true;
}
}  // namespace

Status FieldError(const std::string& file, const std::string& path, const std::string& message) {
  std::string m;
  if (!file.empty()) m += file + ": ";
  if (!path.empty()) m += path + ": ";
  return Status::Error(m + message);
}

std::string TypeName(const Json& j) {
  switch (j.type()) {
    case Json::value_t::null: return "null";
    case Json::value_t::object: return "an object";
    case Json::value_t::array: return "an array";
    case Json::value_t::string: return "a string";
    case Json::value_t::boolean: return "a boolean";
    case Json::value_t::number_integer:
    case Json::value_t::number_unsigned: return "an integer";
    case Json::value_t::number_float: return "a number";
    default: return "an unsupported value";
  }
}

Status ParseJsonText(std::string_view text, const std::string& file, Json* out) {
  try {
    *out = Json::parse(text.begin(), text.end(), /*cb=*/nullptr, /*allow_exceptions=*/true,
                       /*ignore_comments=*/true);
  } catch (const Json::parse_error& e) {
    // e.byte is the 1-based index of the byte where the parser stopped.
    size_t byte = e.byte == 0 ? 0 : std::min<size_t>(e.byte - 1, text.size());
    int line = 1, column = 1;
    for (size_t i = 0; i < byte; ++i) {
      if (text[i] == '\n') {
        ++line;
        column = 1;
      } else {
        ++column;
      }
    }
    std::string what = e.what();
    // nlohmann prefixes "[json.exception.parse_error.101] parse error at line L, column C: ".
    if (auto colon = what.find(": "); colon != std::string::npos) what = what.substr(colon + 2);
    return Status::Error(file + ":" + std::to_string(line) + ":" + std::to_string(column) +
                         ": syntax error: " + what);
  } catch (const Json::exception& e) {
    // e.g. out_of_range 406: a number literal beyond double range ("1e400").
    std::string what = e.what();
    if (auto bracket = what.find("] "); bracket != std::string::npos) what = what.substr(bracket + 2);
    return Status::Error(file + ": " + what);
  }
  return Status::Ok();
}

FieldReader::FieldReader(const Json& object, std::string path, std::string file)
    : object_(object), path_(std::move(path)), file_(std::move(file)) {
  if (!object_.is_object()) {
    status_ = FieldError(file_, path_.empty() ? "(root)" : path_,
                         "expected an object, found " + TypeName(object_));
  }
}

std::string FieldReader::Path(std::string_view key) const {
  if (path_.empty()) return std::string(key);
  if (!key.empty() && key.front() == '[') return path_ + std::string(key);
  return path_ + "." + std::string(key);
}

void FieldReader::Fail(std::string_view key, const std::string& message) {
  if (status_.ok()) status_ = FieldError(file_, key.empty() ? path_ : Path(key), message);
}

bool FieldReader::Has(std::string_view key) { return Get(key) != nullptr; }

const Json* FieldReader::Get(std::string_view key) {
  known_.emplace(key);
  if (!object_.is_object()) return nullptr;
  auto it = object_.find(std::string(key));
  return it == object_.end() ? nullptr : &*it;
}

void FieldReader::Float(std::string_view key, float* out, bool required, float min, float max) {
  const Json* v = Get(key);
  if (!ok()) return;
  if (!v) {
    if (required) Fail(key, "missing (a number)");
    return;
  }
  if (!v->is_number()) return Fail(key, "expected a number, found " + TypeName(*v));
  double d = v->get<double>();
  if (!std::isfinite(d) || d < min || d > max) {
    return Fail(key, "value " + v->dump() + " out of range [" + Json(min).dump() + ", " +
                         Json(max).dump() + "]");
  }
  *out = float(d);
}

void FieldReader::Int(std::string_view key, int* out, bool required, int min, int max) {
  const Json* v = Get(key);
  if (!ok()) return;
  if (!v) {
    if (required) Fail(key, "missing (an integer)");
    return;
  }
  if (!v->is_number_integer()) return Fail(key, "expected an integer, found " + TypeName(*v));
  int64_t i = v->is_number_unsigned() ? int64_t(std::min<uint64_t>(v->get<uint64_t>(), INT64_MAX))
                                      : v->get<int64_t>();
  if (i < min || i > max) {
    return Fail(key, "value " + std::to_string(i) + " out of range [" + std::to_string(min) + ", " +
                         std::to_string(max) + "]");
  }
  *out = int(i);
}

void FieldReader::Uint32(std::string_view key, uint32_t* out, uint32_t min, uint32_t max) {
  const Json* v = Get(key);
  if (!ok() || !v) return;
  if (!v->is_number_integer()) return Fail(key, "expected an integer, found " + TypeName(*v));
  if (v->is_number_integer() && !v->is_number_unsigned() && v->get<int64_t>() < 0) {
    return Fail(key, "value " + v->dump() + " out of range [" + std::to_string(min) + ", " +
                         std::to_string(max) + "]");
  }
  uint64_t u = v->get<uint64_t>();
  if (u < min || u > max) {
    return Fail(key, "value " + std::to_string(u) + " out of range [" + std::to_string(min) + ", " +
                         std::to_string(max) + "]");
  }
  *out = uint32_t(u);
}

void FieldReader::Bool(std::string_view key, bool* out) {
  const Json* v = Get(key);
  if (!ok() || !v) return;
  if (!v->is_boolean()) return Fail(key, "expected true or false, found " + TypeName(*v));
  *out = v->get<bool>();
}

void FieldReader::String(std::string_view key, std::string* out, bool required) {
  const Json* v = Get(key);
  if (!ok()) return;
  if (!v) {
    if (required) Fail(key, "missing (a string)");
    return;
  }
  if (!v->is_string()) return Fail(key, "expected a string, found " + TypeName(*v));
  *out = v->get<std::string>();
}

void FieldReader::Vector3(std::string_view key, Vec3* out, bool required) {
  const Json* v = Get(key);
  if (!ok()) return;
  if (!v) {
    if (required) Fail(key, "missing (an array of 3 numbers)");
    return;
  }
  if (!v->is_array() || v->size() != 3) {
    return Fail(key, "expected an array of 3 numbers, found " +
                         (v->is_array() ? "an array of " + std::to_string(v->size()) : TypeName(*v)));
  }
  Vec3 r;
  for (int i = 0; i < 3; ++i) {
    const Json& e = (*v)[size_t(i)];
    if (!AsFiniteFloat(e, &r[i])) {
      return Fail(std::string(key) + "[" + std::to_string(i) + "]",
                  "expected a finite number within float range, found " + (e.is_number() ? e.dump() : TypeName(e)));
    }
  }
  *out = r;
}

void FieldReader::Vector2(std::string_view key, Vec2* out) {
  const Json* v = Get(key);
  if (!ok() || !v) return;
  float a = 0, b = 0;
  if (AsFiniteFloat(*v, &a)) {
    *out = {a, a};
    return;
  }
  if (!v->is_array() || v->size() != 2 || !AsFiniteFloat((*v)[0], &a) || !AsFiniteFloat((*v)[1], &b)) {
    return Fail(key, "expected a finite number or an array of 2 finite numbers, found " +
                         (v->is_number() ? v->dump() : TypeName(*v)));
  }
  *out = {a, b};
}

void FieldReader::Color(std::string_view key, RGB* out, bool required) {
  const Json* v = Get(key);
  if (!ok()) return;
  if (!v) {
    if (required) Fail(key, "missing (a colour: 3 numbers or one number)");
    return;
  }
  if (v->is_number()) {
    float f = v->get<float>();
    if (!(f >= 0.f) || !std::isfinite(f)) return Fail(key, "a colour must be finite and >= 0");
    *out = RGB::Gray(f);
    return;
  }
  if (!v->is_array() || v->size() != 3) {
    return Fail(key, "expected a colour (an array of 3 numbers or one number), found " +
                         (v->is_array() ? "an array of " + std::to_string(v->size()) : TypeName(*v)));
  }
  RGB c;
  for (int i = 0; i < 3; ++i) {
    const Json& e = (*v)[size_t(i)];
    if (!e.is_number()) {
      return Fail(std::string(key) + "[" + std::to_string(i) + "]",
                  "expected a number, found " + TypeName(e));
    }
    float f = e.get<float>();
    if (!(f >= 0.f) || !std::isfinite(f)) return Fail(key, "a colour must be finite and >= 0");
    c[i] = f;
  }
  *out = c;
}

Status FieldReader::Finish() {
  if (!status_.ok()) return status_;
  for (auto it = object_.begin(); it != object_.end(); ++it) {
    if (!known_.count(it.key())) {
      std::string allowed;
      for (const auto& k : known_) allowed += (allowed.empty() ? "" : ", ") + k;
      return FieldError(file_, Path(it.key()), "unknown key (expected one of: " + allowed + ")");
    }
  }
  return Status::Ok();
}

}  // namespace dcm::embree
