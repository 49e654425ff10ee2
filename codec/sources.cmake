# The sources of geomip::codec, shared with the standalone fuzz build (tests/fuzz).
set(GEOMIP_CODEC_SOURCES
  arithmetic_coder.cpp
  bitplane_coder.cpp
  geometry_codec.cpp
  layout_code.cpp
  normal_layers.cpp
  normal_mesh.cpp
  pack.cpp
  status.cpp
  wavelet.cpp
)
