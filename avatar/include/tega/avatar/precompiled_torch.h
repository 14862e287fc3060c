// The libtorch headers nearly every avatar translation unit includes. CMake
// precompiles them (tega_use_torch_pch): parsing them took about half of each
// such unit's compile time. Sources still include what they use themselves.
#pragma once

#include <ATen/ATen.h>
#include <ATen/Parallel.h>
#include <ATen/core/grad_mode.h>
#include <torch/csrc/autograd/autograd.h>
#include <torch/csrc/autograd/custom_function.h>
#include <torch/nn/module.h>
