// Options by name, as the C API (dcm/dcm.h) and the Python module set them:
// the snake_case names of ReconstructionOptions' fields ("contrast_threshold",
// "elementary_block", "texture_split", ...), one table for both.
#pragma once

#include <string_view>
#include <vector>

#include "dcm/options.h"
#include "dcm/status.h"

namespace dcm {

/// The kind of value a named option takes.
enum class OptionKind { kUnknown, kString, kInt, kFloat, kBool };

/// The kind of the option `name`; kUnknown for no such option.
OptionKind KindOfOption(std::string_view name);

/// Sets an integer option; false when `name` is no integer option. 0 unsets
/// one with a regime-aware default ("elementary_block", "directions").
bool SetIntOption(ReconstructionOptions& o, std::string_view name, int value);
/// Sets a float option; false when `name` is no float option. A negative
/// value unsets one with a regime-aware default ("contrast_threshold").
bool SetFloatOption(ReconstructionOptions& o, std::string_view name, float value);
/// The value of an integer option in `*value` (0 for an unset regime-aware
/// one); false when `name` is no integer option.
bool GetIntOption(const ReconstructionOptions& o, std::string_view name, int* value);
/// The value of a float option in `*value` (-1 for an unset regime-aware
/// one); false when `name` is no float option.
bool GetFloatOption(const ReconstructionOptions& o, std::string_view name, float* value);
/// The field of `o` behind a bool option; nullptr when `name` is none.
bool* FindBoolOption(ReconstructionOptions& o, std::string_view name);

/// Sets a string option: "method" ("dcm", "paper" or "guo"; resets every
/// option to that preset), "object_test", "thin_objects", "contrast_metric"
/// (these two: "default" unsets them), "smooth_refinement". The message
/// names the option and the valid values ("unknown string option 'NAME'" for
/// a name that is none of these).
Status SetStringOption(ReconstructionOptions* o, std::string_view name, std::string_view value);

/// Unsets an option with a regime-aware default ("elementary_block",
/// "contrast_threshold", "contrast_metric", "directions", "thin_objects"):
/// dcm's value for the regime applies (ResolveSettings). An error naming any
/// other option.
Status ResetOption(ReconstructionOptions* o, std::string_view name);

/// Every option name of one kind, in the table's order (for messages).
std::vector<std::string_view> OptionNames(OptionKind kind);

}  // namespace dcm
