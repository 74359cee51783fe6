// The texture split (paper 3.3): L = L_i tau + L_c, with (L_i, L_c)
// interpolated and tau re-applied per pixel. Settings::split decides whether
// a reconstruction uses it; SampleStore keeps (L_i, L_c) per exact pixel and
// Value carries them. Here: where tau lets the split work.
#pragma once

#include <vector>

#include "dcm/color.h"
#include "sample_store.h"

namespace dcm::detail {

/// tau is exactly zero in all three channels (L = L_c): a surface without
/// diffuse texture (the sky, chrome, an emitter, a black texel), where L_i
/// means nothing.
/// (`&`: without branches, as IsFinite.)
inline bool TauZero(RGB tau) { return (tau.r == 0.f) & (tau.g == 0.f) & (tau.b == 0.f); }

/// L_i = L_t / tau is recoverable: tau is finite and neither zero nor
/// denormal in every channel.
bool TauRecoverable(RGB tau);

/// Requests every pixel whose tau is not finite: it cannot be reconstructed
/// as L_i tau + L_c, so it is evaluated exactly.
void RequestNonFiniteTau(const std::vector<RGB>& tau, SampleStore& store);

}  // namespace dcm::detail
