# tega_library(NAME SOURCES ... [PUBLIC_LINK ...] [PRIVATE_LINK ...])
# A stage library whose public headers live in <folder>/include.
function(tega_library name)
  cmake_parse_arguments(ARG "" "" "SOURCES;PUBLIC_LINK;PRIVATE_LINK" ${ARGN})
  add_library(${name} STATIC ${ARG_SOURCES})
  target_include_directories(${name} PUBLIC ${CMAKE_CURRENT_SOURCE_DIR}/include)
  target_link_libraries(${name} PUBLIC ${ARG_PUBLIC_LINK} PRIVATE ${ARG_PRIVATE_LINK})
  target_compile_options(${name} PRIVATE $<$<COMPILE_LANGUAGE:CXX>:-Wall -Wextra>)
endfunction()

# tega_test(NAME SOURCES ... LINK ...): one GoogleTest executable registered with CTest.
# Tests run from the build folder; TEGA_SHARED_DATA points at ../shared/data
# (tests that need it skip cleanly when it is absent).
function(tega_test name)
  cmake_parse_arguments(ARG "" "" "SOURCES;LINK" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE ${ARG_LINK} tega_test_support GTest::gtest GTest::gtest_main)
  gtest_discover_tests(${name} DISCOVERY_TIMEOUT 120
    PROPERTIES ENVIRONMENT "TEGA_SHARED_DATA=${TEGA_SHARED_DATA_DIR}")
endfunction()

function(tega_print_summary)
  message(STATUS "tega configuration:")
  message(STATUS "  OpenImageIO (JPEG/TIFF/EXR)  ${TEGA_HAVE_OPENIMAGEIO}")
  message(STATUS "  OpenCV (calibration take)    ${TEGA_HAVE_OPENCV}")
  if(TEGA_HAVE_OPENCV AND TEGA_HAVE_CERES)
    set(calibrate ON)
  else()
    set(calibrate OFF)
  endif()
  message(STATUS "  calibrate/ (OpenCV + Ceres)  ${calibrate}")
  message(STATUS "  capture/ (Aravis)            ${TEGA_HAVE_ARAVIS}")
  message(STATUS "  mvs/ depth estimation        ON")
  message(STATUS "  mvs/ meshing (Open3D+OpenCV) ${TEGA_HAVE_OPEN3D}")
  message(STATUS "  avatar/ (libtorch)           ${TEGA_BUILD_AVATAR}")
  message(STATUS "  CUDA kernels                 ${TEGA_HAVE_CUDA}")
  message(STATUS "  tests                        ${TEGA_BUILD_TESTS}")
endfunction()
