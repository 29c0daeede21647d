# Every third-party dependency comes from a Debian bookworm package installed by setup.sh.
# Nothing is downloaded at configure or build time.
find_package(Eigen3 3.4 REQUIRED NO_MODULE)
find_package(Ceres REQUIRED)
find_package(OpenCV REQUIRED COMPONENTS core imgproc imgcodecs video calib3d features2d)
# PCL's optional VTK dependency (visualisation only) drags in VTK's MPI targets, which Debian's
# VTK config cannot resolve without MPI; gvio never includes VTK headers, so skip it.
set(CMAKE_DISABLE_FIND_PACKAGE_VTK ON)
find_package(PCL REQUIRED COMPONENTS common io filters kdtree)
unset(CMAKE_DISABLE_FIND_PACKAGE_VTK)
find_package(octomap REQUIRED)
# GDAL/OGR: GeoJSON, KML and GPX exports and the WKT of UTM coordinate systems (LAS).
find_package(GDAL CONFIG REQUIRED)
find_package(yaml-cpp REQUIRED)
find_package(CLI11 REQUIRED)
find_package(fmt REQUIRED)
find_package(spdlog REQUIRED)
find_package(nlohmann_json REQUIRED)
find_package(ZLIB REQUIRED)
find_package(Threads REQUIRED)
find_package(PkgConfig REQUIRED)
pkg_check_modules(EPOXY REQUIRED IMPORTED_TARGET epoxy)
pkg_check_modules(EGL REQUIRED IMPORTED_TARGET egl)
pkg_check_modules(CAIRO REQUIRED IMPORTED_TARGET cairo)

# GeographicLib ships only a Find module on Debian (in /usr/share/cmake/geographiclib).
list(APPEND CMAKE_MODULE_PATH /usr/share/cmake/geographiclib)
find_package(GeographicLib REQUIRED)
add_library(gvio_geographiclib INTERFACE)
target_include_directories(gvio_geographiclib SYSTEM INTERFACE ${GeographicLib_INCLUDE_DIRS})
target_link_libraries(gvio_geographiclib INTERFACE ${GeographicLib_LIBRARIES})

# OctoMap's package config exports variables, not targets: wrap them so includes stay SYSTEM.
add_library(gvio_octomap INTERFACE)
target_include_directories(gvio_octomap SYSTEM INTERFACE ${OCTOMAP_INCLUDE_DIRS})
target_link_libraries(gvio_octomap INTERFACE ${OCTOMAP_LIBRARIES})

# PCL exports targets but also plain include lists; mark them SYSTEM so its headers do not
# trip the project's warnings.
add_library(gvio_pcl INTERFACE)
target_include_directories(gvio_pcl SYSTEM INTERFACE ${PCL_INCLUDE_DIRS})
target_link_libraries(gvio_pcl INTERFACE ${PCL_LIBRARIES})
target_compile_definitions(gvio_pcl INTERFACE ${PCL_DEFINITIONS})

if(GVIO_BUILD_TESTS)
  find_package(GTest REQUIRED)
  find_package(benchmark REQUIRED)
endif()
