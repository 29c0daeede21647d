#pragma once
// The groups of fuzz targets (harness.hpp targets() lists them all).
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "fuzz/harness.hpp"

namespace gvio::fuzz {

void addTextTargets(std::vector<Target>& out);  // targets_text.cpp
// A target whose input is one file with `seed` as its valid instance (targets_text.cpp).
Target plain(std::string name, std::string file, std::string seed,
             std::function<void(const std::filesystem::path&)> read);
// A Kalibr camchain of a 32 x 16 px radtan stereo pair on /cam0/image_raw, /cam1/image_raw.
std::string smallCamchainYaml();
void addFileTargets(std::vector<Target>& out);   // targets_files.cpp
void addFleetTargets(std::vector<Target>& out);  // targets_fleet.cpp
void addRos2Targets(std::vector<Target>& out);   // targets_ros2.cpp

}  // namespace gvio::fuzz
