// Strict reading of JSON objects: every key must be known, every value of the
// expected type, and every error names the key path ("objects[3].radius") and
// the file.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <string_view>

#include "dcm/color.h"
#include "dcm/status.h"
#include "dcm/embree/vec3.h"

namespace dcm::embree {

/// JSON that keeps the order of keys (material indices follow the file).
using Json = nlohmann::ordered_json;

/// Parses `text` as JSON (comments allowed). A syntax error is reported as
/// "FILE:LINE:COLUMN: syntax error: ..." with the 1-based position of the byte
/// where parsing stopped.
Status ParseJsonText(std::string_view text, const std::string& file, Json* out);

/// Reads the fields of one JSON object. Each getter marks its key as known;
/// Finish() reports keys that no getter asked for. The first error sticks and
/// later calls do nothing.
class FieldReader {
 public:
  /// `path` is the key path of `object` ("" for the root), `file` the file name
  /// used in messages.
  FieldReader(const Json& object, std::string path, std::string file);

  /// True when the key is present (and marks it as known).
  bool Has(std::string_view key);
  /// The value of `key` or nullptr when absent (marks it as known).
  const Json* Get(std::string_view key);

  void Float(std::string_view key, float* out, bool required = false,
             float min = -1e30f, float max = 1e30f);
  void Int(std::string_view key, int* out, bool required = false, int min = INT32_MIN,
           int max = INT32_MAX);
  void Uint32(std::string_view key, uint32_t* out, uint32_t min, uint32_t max);
  void Bool(std::string_view key, bool* out);
  void String(std::string_view key, std::string* out, bool required = false);
  /// Three numbers.
  void Vector3(std::string_view key, Vec3* out, bool required = false);
  /// Two numbers, or one number for both.
  void Vector2(std::string_view key, Vec2* out);
  /// Three non-negative numbers, or one number for gray.
  void Color(std::string_view key, RGB* out, bool required = false);

  /// Records an error about `key` (or the object itself when `key` is empty).
  void Fail(std::string_view key, const std::string& message);
  /// The key path of a child key or array element, e.g. Path("radius").
  std::string Path(std::string_view key) const;

  bool ok() const { return status_.ok(); }
  const Status& status() const { return status_; }
  /// Reports the first unknown key, or the first error seen.
  Status Finish();

 private:
  const Json& object_;
  std::string path_;
  std::string file_;
  std::set<std::string, std::less<>> known_;
  Status status_;
};

/// "FILE: PATH: MESSAGE" (parts left out when empty).
Status FieldError(const std::string& file, const std::string& path, const std::string& message);

/// A JSON type name for messages ("a string", "an array", ...).
std::string TypeName(const Json& j);

}  // namespace dcm::embree
