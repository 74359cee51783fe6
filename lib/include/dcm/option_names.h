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

/// The field of `o` behind an integer, float or bool option; nullptr when
/// `name` is not an option of that kind.
int* FindIntOption(ReconstructionOptions& o, std::string_view name);
float* FindFloatOption(ReconstructionOptions& o, std::string_view name);
bool* FindBoolOption(ReconstructionOptions& o, std::string_view name);

/// Sets a string option: "method" ("dcm", "paper" or "guo"; resets every
/// option to that preset), "object_test", "thin_objects",
/// "thin_objects_supersampled", "contrast_metric",
/// "contrast_metric_supersampled", "smooth_refinement". The message names
/// the option and the valid values ("unknown string option 'NAME'" for a
/// name that is none of these).
Status SetStringOption(ReconstructionOptions* o, std::string_view name, std::string_view value);

/// Every option name of one kind, in the table's order (for messages).
std::vector<std::string_view> OptionNames(OptionKind kind);

}  // namespace dcm
