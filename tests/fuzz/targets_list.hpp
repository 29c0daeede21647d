#pragma once
// The groups of fuzz targets (harness.hpp targets() lists them all).
#include <string>
#include <vector>

#include "fuzz/harness.hpp"

namespace gvio::fuzz {

void addTextTargets(std::vector<Target>& out);  // targets_text.cpp
// A Kalibr camchain of a 32 x 16 px radtan stereo pair on /cam0/image_raw, /cam1/image_raw.
std::string smallCamchainYaml();
void addFileTargets(std::vector<Target>& out);   // targets_files.cpp
void addFleetTargets(std::vector<Target>& out);  // targets_fleet.cpp

}  // namespace gvio::fuzz
