# The sources of geomip::codec, shared with the standalone fuzz build (tests/fuzz).
set(GEOMIP_CODEC_SOURCES
  pack.cpp
  status.cpp
)
