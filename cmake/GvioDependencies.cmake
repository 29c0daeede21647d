# Every third-party dependency comes from a Debian bookworm package installed by setup.sh.
# Nothing is downloaded at configure or build time.
find_package(Eigen3 3.4 REQUIRED NO_MODULE)
find_package(Ceres REQUIRED)
find_package(OpenCV REQUIRED COMPONENTS core imgproc imgcodecs video videoio calib3d features2d)
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
# ROS 2 bags: MCAP chunks compressed with zstd or lz4 (frame format), sqlite3 storage (.db3).
pkg_check_modules(ZSTD REQUIRED IMPORTED_TARGET libzstd)
pkg_check_modules(LZ4 REQUIRED IMPORTED_TARGET liblz4)
pkg_check_modules(SQLITE3 REQUIRED IMPORTED_TARGET sqlite3)
# gvio view --serve: a read-only static file server on loopback.
pkg_check_modules(HTTPLIB REQUIRED IMPORTED_TARGET cpp-httplib)

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

# ROS1 bags without ROS: Debian's librosbag-storage-dev with the sensor_msgs message headers. Its
# pkg-config file requires a pluginlib.pc that Debian does not ship, so the pieces are found one by
# one; pluginlib (ROS 2's, which bag.h includes for encryption plugins) keeps its headers one
# folder down.
pkg_check_modules(ROSCPP_SERIALIZATION REQUIRED IMPORTED_TARGET roscpp_serialization rostime
                  cpp_common roslz4)
find_library(ROSBAG_STORAGE_LIBRARY rosbag_storage REQUIRED)
find_library(CONSOLE_BRIDGE_LIBRARY console_bridge REQUIRED)
find_path(PLUGINLIB_INCLUDE_DIR pluginlib/class_loader.hpp PATH_SUFFIXES pluginlib REQUIRED)
find_path(CLASS_LOADER_INCLUDE_DIR class_loader/class_loader.hpp PATH_SUFFIXES class_loader
          REQUIRED)
find_path(RCUTILS_INCLUDE_DIR rcutils/types.h PATH_SUFFIXES rcutils REQUIRED)
find_path(RCPPUTILS_INCLUDE_DIR rcpputils/filesystem_helper.hpp PATH_SUFFIXES rcpputils REQUIRED)
find_path(AMENT_INDEX_INCLUDE_DIR ament_index_cpp/get_resource.hpp PATH_SUFFIXES ament_index_cpp
          REQUIRED)
find_path(SENSOR_MSGS_INCLUDE_DIR sensor_msgs/Image.h REQUIRED)
find_package(Boost REQUIRED COMPONENTS filesystem)
find_package(BZip2 REQUIRED)  # the record check decompresses bz2 chunks as librosbag does
add_library(gvio_rosbag_deps INTERFACE)
target_include_directories(gvio_rosbag_deps SYSTEM INTERFACE
  ${PLUGINLIB_INCLUDE_DIR} ${CLASS_LOADER_INCLUDE_DIR} ${RCUTILS_INCLUDE_DIR}
  ${RCPPUTILS_INCLUDE_DIR} ${AMENT_INDEX_INCLUDE_DIR} ${SENSOR_MSGS_INCLUDE_DIR})
target_link_libraries(gvio_rosbag_deps INTERFACE ${ROSBAG_STORAGE_LIBRARY} ${CONSOLE_BRIDGE_LIBRARY}
                                                 PkgConfig::ROSCPP_SERIALIZATION Boost::filesystem)
