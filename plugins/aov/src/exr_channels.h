// The channels of one or several EXR files of one resolution, looked up by
// name and read one plane at a time, with the checks every input needs.
#pragma once

#include <OpenImageIO/imageio.h>

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "dcm/geometry.h"
#include "dcm/status.h"

namespace dcm::aov::detail {

/// Upper bound on either side of an image.
inline constexpr int kMaxSide = 1 << 17;
/// Planes (RGB roles, IDs, mask, read buffers) the provider may allocate per
/// pixel, checked against dcm::MemoryBudget() from the headers before
/// anything is allocated.
inline constexpr int kPlanesPerPixel = 24;
/// A part of a scanline file whose channels take at most this many bytes as
/// float is read in one pass at its first float read (ChannelSet::ReadFloat),
/// when no wanted channels were named (ChannelSet::Want).
inline constexpr int64_t kOnePassBytes = int64_t(1) << 30;

/// Where a channel lives.
struct ChannelRef {
  int file = 0;
  int subimage = 0;
  int index = 0;
  OIIO::TypeDesc format;
};

/// A Cryptomatte layer: rank-0 IDs in `<name>00.R` (float bits of a uint32
/// hash), the coverage of rank 2k in `<name>0k.G` and of rank 2k+1 in
/// `<name>0k.A`, names in the manifest of the EXR metadata.
struct CryptoLayer {
  std::string name;     ///< as in "cryptomatte/<key>/name"
  std::string channel;  ///< the rank-0 ID channel
  ChannelRef ref;
  std::vector<std::string> coverage;  ///< the coverage channels of every rank stored
  std::map<std::string, uint32_t> manifest;  ///< object/material name -> ID
};

/// Where an EXR's pixels lie: its data window, inside (a render region) or
/// around (overscan) its display window, the frame.
struct ImageWindows {
  Bounds2i data;
  Bounds2i display;
  bool cropped() const { return !(data == display); }
  /// "200x150 at 30,40 of 256x256 at 0,0", for messages.
  std::string Text() const;
  /// "(x, y)": pixel i of the data window (row-major) in frame coordinates,
  /// for messages.
  std::string PixelText(size_t i) const;
  friend bool operator==(const ImageWindows&, const ImageWindows&) = default;
};

class ChannelSet {
 public:
  ChannelSet();
  ~ChannelSet();
  ChannelSet(ChannelSet&&) noexcept;
  ChannelSet& operator=(ChannelSet&&) noexcept;

  /// Opens `path`: it must exist, be an OpenEXR file, not deep, of sane
  /// dimensions, and have the same data and display windows as the files
  /// added before. Channels already present keep their first file. The
  /// pixels are those of the data window.
  Status Add(const std::string& path);

  int width() const { return windows_.data.width(); }
  int height() const { return windows_.data.height(); }
  const ImageWindows& windows() const { return windows_; }
  size_t pixels() const { return size_t(windows_.data.area()); }
  bool empty() const { return files_.empty(); }

  std::optional<ChannelRef> Find(const std::string& name) const;
  bool Has(const std::string& name) const { return Find(name).has_value(); }
  /// Every channel name (sorted).
  std::vector<std::string> Names() const;
  /// "'a.exr': R, G, B; 'b.exr': id" (at most ~100 names), for messages.
  std::string Describe() const;
  const std::string& Path(int file) const;
  /// The files, for messages ("'a.exr'" or "'a.exr', 'b.exr'").
  std::string Paths() const;

  /// Names the channels that will be read as float: the one-pass read of a
  /// part then decodes and keeps those alone, whatever the part's size.
  /// Unknown names are ignored.
  void Want(const std::vector<std::string>& names);
  /// Reads a channel as float (any stored format).
  Status ReadFloat(const std::string& name, std::vector<float>* plane) const;
  /// Reads an ID channel: uint channels as UINT32, float/half channels as
  /// float checked to hold integers (negative integers wrap to uint32).
  Status ReadId(const std::string& name, std::vector<uint32_t>* plane) const;
  /// Reads a Cryptomatte layer's rank-0 IDs: the float bits as uint32. A
  /// pixel whose footprint mostly saw no object (the share no rank covers
  /// exceeds rank 0's: the sky through a window, where one sample of the
  /// pixel hit the frame) gets ID 0, the background, which no Cryptomatte
  /// hash takes.
  Status ReadCrypto(const CryptoLayer& layer, std::vector<uint32_t>* plane) const;

  /// The Cryptomatte layers found in the metadata.
  const std::vector<CryptoLayer>& Crypto() const { return crypto_; }
  /// The layer whose name equals `name` or ends with it; error when none or
  /// ambiguous.
  Status FindCrypto(const std::string& name, const CryptoLayer** layer) const;

 private:
  struct File {
    std::string path;
    std::unique_ptr<OIIO::ImageInput> in;
    std::vector<OIIO::ImageSpec> specs;  ///< per subimage (EXR part)
  };
  Status ReadRaw(const std::string& name, OIIO::TypeDesc type, void* data) const;
  Status ReadRef(const ChannelRef& ref, const std::string& name, OIIO::TypeDesc type,
                 void* data) const;
  /// EXR compresses blocks of scanlines with all their channels together, so
  /// reading one channel at a time decompresses a file once per channel (24
  /// times for a Blender multilayer EXR in dense mode). A part of a scanline
  /// file is read in one pass instead, at its first float read: the wanted
  /// channels (Want), or without any every channel when they fit in
  /// kOnePassBytes. ReadFloat then takes a channel's plane from it (a second
  /// read of the channel reads the file again). Empty when the part is
  /// tiled, too large, or the pass failed (the per-channel read then reports
  /// the error, naming the channel); a plane not read is empty.
  std::vector<std::vector<float>>& OnePass(int file, int subimage) const;
  struct Pass {
    bool tried = false;
    std::vector<std::vector<float>> planes;  ///< per channel of the part
  };
  mutable std::map<std::pair<int, int>, Pass> passes_;
  /// Per (file, part): 1 for each channel index named by Want(); empty map:
  /// nothing named.
  std::map<std::pair<int, int>, std::vector<uint8_t>> wanted_;
  void ScanCrypto(int file);

  ImageWindows windows_;
  std::vector<File> files_;
  std::map<std::string, ChannelRef> channels_;
  std::vector<CryptoLayer> crypto_;
};

/// "'name'" quoted for messages.
inline std::string Quote(const std::string& s) { return "'" + s + "'"; }

}  // namespace dcm::aov::detail
