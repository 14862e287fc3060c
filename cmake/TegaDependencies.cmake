# Finds the project's dependencies. Required ones stop the configure step with
# a message naming the Debian package; optional ones switch the parts that
# need them off (see tega_print_summary()).

macro(tega_require package debian_package)
  find_package(${package} ${ARGN} QUIET)
  if(NOT ${package}_FOUND)
    message(FATAL_ERROR "tega needs ${package}: install it with scripts/install-deps "
                        "(Debian package ${debian_package})")
  endif()
endmacro()

tega_require(Eigen3 libeigen3-dev NO_MODULE)
tega_require(nlohmann_json nlohmann-json3-dev)
tega_require(yaml-cpp libyaml-cpp-dev)
tega_require(spdlog libspdlog-dev)
tega_require(CLI11 libcli11-dev)
tega_require(PNG libpng-dev)
# gzip streams of SPZ splat files (tega export --format spz).
tega_require(ZLIB zlib1g-dev)
# SHA-256 of the orchestrator's manifests (libcrypto's EVP interface).
tega_require(OpenSSL libssl-dev)
# OpenMesh: core's mesh tools (decimation, smoothing, adjacency,
# components; tega/core/mesh_tools.h). Debian's config exports the targets
# OpenMeshCore and OpenMeshTools with paths relative to the config file itself,
# so an unpacked copy (scripts/gpu-carry: .carry/openmesh/usr) is found through
# CMAKE_PREFIX_PATH or OpenMesh_DIR like the system one.
tega_require(OpenMesh libopenmesh-dev CONFIG)
find_package(Threads REQUIRED)

# yaml-cpp 0.7 (Debian) exports "yaml-cpp"; newer releases "yaml-cpp::yaml-cpp".
if(TARGET yaml-cpp::yaml-cpp)
  set(TEGA_YAML_TARGET yaml-cpp::yaml-cpp)
else()
  set(TEGA_YAML_TARGET yaml-cpp)
endif()

if(TEGA_BUILD_TESTS)
  tega_require(GTest libgtest-dev)
endif()

set(TEGA_HAVE_OPENIMAGEIO OFF)
if(TEGA_WITH_OPENIMAGEIO)
  find_package(OpenImageIO QUIET)
  if(OpenImageIO_FOUND)
    set(TEGA_HAVE_OPENIMAGEIO ON)
  else()
    message(STATUS "tega: OpenImageIO not found (libopenimageio-dev): only PNG image I/O is built")
  endif()
endif()

set(TEGA_HAVE_OPENCV OFF)
if(TEGA_WITH_OPENCV)
  find_package(OpenCV QUIET COMPONENTS core imgproc aruco videoio calib3d ximgproc)
  if(OpenCV_FOUND)
    set(TEGA_HAVE_OPENCV ON)
  else()
    message(STATUS "tega: OpenCV with contrib not found (libopencv-dev libopencv-contrib-dev): "
                   "the synthetic calibration take and video output are off")
  endif()
endif()

# Ceres: the bundle adjustment of calibrate/ (which also needs OpenCV).
set(TEGA_HAVE_CERES OFF)
find_package(Ceres QUIET)
if(Ceres_FOUND)
  set(TEGA_HAVE_CERES ON)
else()
  message(STATUS "tega: Ceres not found (libceres-dev): calibrate/ is off")
endif()

set(TEGA_HAVE_ARAVIS OFF)
if(TEGA_WITH_ARAVIS)
  find_package(PkgConfig QUIET)
  if(PkgConfig_FOUND)
    pkg_check_modules(ARAVIS QUIET IMPORTED_TARGET aravis-0.8)
  endif()
  if(ARAVIS_FOUND)
    set(TEGA_HAVE_ARAVIS ON)
  else()
    message(STATUS "tega: Aravis 0.8 not found (libaravis-dev libusb-1.0-0-dev): capture/ is off")
  endif()
endif()

# cpp-httplib: `tega serve`, the browser player's HTTP server. Debian builds
# it as a library with OpenSSL, zlib and Brotli; its pkg-config file carries
# the matching CPPHTTPLIB_* definitions, without which the header's classes
# would not match the library's.
set(TEGA_HAVE_HTTPLIB OFF)
find_package(PkgConfig QUIET)
if(PkgConfig_FOUND)
  pkg_check_modules(HTTPLIB QUIET IMPORTED_TARGET cpp-httplib)
endif()
if(HTTPLIB_FOUND)
  set(TEGA_HAVE_HTTPLIB ON)
else()
  message(STATUS "tega: cpp-httplib not found (libcpp-httplib-dev): tega serve is off")
endif()

set(TEGA_HAVE_TORCH OFF)
if(TEGA_BUILD_AVATAR)
  find_package(Torch QUIET)
  if(Torch_FOUND)
    set(TEGA_HAVE_TORCH ON)
  else()
    message(STATUS "tega: libtorch not found (libtorch-dev): avatar/ is off")
    set(TEGA_BUILD_AVATAR OFF)
  endif()
endif()

# Open3D: surface reconstruction and point-cloud tools of mvs/.
set(TEGA_HAVE_OPEN3D OFF)
find_package(Open3D QUIET)
if(Open3D_FOUND)
  set(TEGA_HAVE_OPEN3D ON)
else()
  message(STATUS "tega: Open3D not found (libopen3d-dev): mvs/ builds its depth estimation only")
endif()

# dlib: 68-point landmark predictors for tracking/.
set(TEGA_HAVE_DLIB OFF)
find_package(dlib QUIET)
if(dlib_FOUND)
  set(TEGA_HAVE_DLIB ON)
else()
  message(STATUS "tega: dlib not found (libdlib-dev): tracking/ is off")
endif()

# nvcc compiles the kernels of avatar/ and of mvs/'s depth estimation; no GPU
# is needed to build them.
set(TEGA_HAVE_CUDA OFF)
if(TEGA_WITH_CUDA)
  include(CheckLanguage)
  if(NOT CMAKE_CUDA_COMPILER AND EXISTS /usr/local/cuda/bin/nvcc)
    set(CMAKE_CUDA_COMPILER /usr/local/cuda/bin/nvcc)
  endif()
  check_language(CUDA)
  if(CMAKE_CUDA_COMPILER)
    if(NOT DEFINED CMAKE_CUDA_ARCHITECTURES)
      set(CMAKE_CUDA_ARCHITECTURES 90)
    endif()
    enable_language(CUDA)
    set(CMAKE_CUDA_STANDARD 17)
    set(CMAKE_CUDA_STANDARD_REQUIRED ON)
    find_package(CUDAToolkit REQUIRED)
    set(TEGA_HAVE_CUDA ON)
  else()
    message(STATUS "tega: nvcc not found: CUDA kernels are off (CPU paths only)")
  endif()
endif()
