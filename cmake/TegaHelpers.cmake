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
# A test executable; ctest runs each of its tests in a process of its own,
# or, with SUITES, each named suite in one process, so that a suite's
# expensive fixture (a rendered virtual-studio capture) is made once.
function(tega_test name)
  cmake_parse_arguments(ARG "" "" "SOURCES;LINK;SUITES" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE ${ARG_LINK} tega_test_support GTest::gtest GTest::gtest_main)
  tega_unity_tests(${name})
  if(ARG_SUITES)
    foreach(suite ${ARG_SUITES})
      add_test(NAME ${suite} COMMAND ${name} --gtest_filter=${suite}.*)
      set_tests_properties(${suite} PROPERTIES ENVIRONMENT "TEGA_SHARED_DATA=${TEGA_SHARED_DATA_DIR}")
    endforeach()
  else()
    gtest_discover_tests(${name} DISCOVERY_TIMEOUT 120
      PROPERTIES ENVIRONMENT "TEGA_SHARED_DATA=${TEGA_SHARED_DATA_DIR}")
  endif()
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
  if(TEGA_HAVE_OPEN3D AND TEGA_HAVE_OPENCV)
    set(mvs_meshing ON)
  else()
    set(mvs_meshing OFF)
  endif()
  message(STATUS "  mvs/ depth estimation        ON")
  message(STATUS "  mvs/ surfaces (Open3D)       ${TEGA_HAVE_OPEN3D}")
  message(STATUS "  mvs/ frames (Open3D+OpenCV)  ${mvs_meshing}")
  if(TEGA_HAVE_OPEN3D AND TEGA_HAVE_OPENCV AND TEGA_HAVE_CERES AND TEGA_HAVE_DLIB)
    set(tracking ON)
  else()
    set(tracking OFF)
  endif()
  message(STATUS "  tracking/ (Ceres+dlib+mvs)   ${tracking}")
  message(STATUS "  avatar/ (libtorch)           ${TEGA_BUILD_AVATAR}")
  message(STATUS "  CUDA kernels                 ${TEGA_HAVE_CUDA}")
  message(STATUS "  tests                        ${TEGA_BUILD_TESTS}")
endfunction()

# tega_unity_tests(TARGET): compiles a test executable's sources a few to a translation
# unit. Template instantiations (libtorch, GoogleTest, Eigen) take most of a
# test file's compile time and are then made once per batch: the avatar tests
# build 3-5 times faster. CUDA parity tests (*_cuda_test.cpp) repeat helpers of
# their CPU twins, so they are batched among themselves.
function(tega_unity_tests target)
  set(batch_size 6)
  get_target_property(sources ${target} SOURCES)
  set(count_cpu 0)
  set(count_cuda 0)
  foreach(source ${sources})
    if(source MATCHES "_cuda_test\\.cpp$")
      set(kind cuda)
    else()
      set(kind cpu)
    endif()
    math(EXPR batch "${count_${kind}} / ${batch_size}")
    math(EXPR count_${kind} "${count_${kind}} + 1")
    set_source_files_properties(${source} TARGET_DIRECTORY ${target} PROPERTIES UNITY_GROUP ${kind}_${batch})
  endforeach()
  set_target_properties(${target} PROPERTIES UNITY_BUILD ON UNITY_BUILD_MODE GROUP)
endfunction()
