#include "tega/nn/safetensors.h"

#include <ATen/ATen.h>
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>

#include "tega/core/error.h"
#include "test_support.h"

namespace tega::nn {
namespace {

std::string read_bytes(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void write_bytes(const std::filesystem::path& file, const std::string& bytes) {
  std::ofstream out(file, std::ios::binary);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

std::string u64_le(uint64_t v) {
  std::string s(8, '\0');
  for (int i = 0; i < 8; ++i) s[i] = static_cast<char>((v >> (8 * i)) & 0xff);
  return s;
}

// A file built by hand from the format description: length, JSON, data.
std::string hand_built(const std::string& json, const std::string& data) {
  return u64_le(json.size()) + json + data;
}

template <class T>
std::string raw(std::initializer_list<T> values) {
  std::string s(values.size() * sizeof(T), '\0');
  std::memcpy(s.data(), std::data(values), s.size());
  return s;
}

// Expects read_safetensors(file) to throw a tega::Error that names the file
// and contains `fragment`.
void expect_read_error(const std::filesystem::path& file, const std::string& fragment) {
  try {
    read_safetensors(file);
    ADD_FAILURE() << "no error for " << file;
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find(file.string()), std::string::npos) << message;
    EXPECT_NE(message.find(fragment), std::string::npos) << message;
  }
}

TEST(Safetensors, RoundTripsDtypesShapesAndMetadata) {
  test::TempDir dir;
  TensorMap tensors{
      {"f32", at::randn({2, 3, 4})},
      {"f64", at::randn({5}, at::kDouble)},
      {"i32", at::arange(-6, 6, at::kInt).view({3, 4})},
      {"i64", at::tensor({int64_t{1} << 40, int64_t{-7}}, at::kLong)},
      {"u8", at::arange(0, 250, 7, at::kByte)},
      {"bf16", at::randn({3, 2}).to(at::kBFloat16)},
      {"f16", at::randn({4}).to(at::kHalf)},
      {"scalar", at::tensor(3.5f).view({})},
      {"empty", at::zeros({0, 3})},
      {"strided", at::randn({4, 6}).t()},  // not contiguous: written in logical order
  };
  const Metadata metadata{{"format", "pt"}, {"iteration", "1200"}};
  const auto file = dir / "checkpoint.safetensors";
  write_safetensors(file, tensors, metadata);

  const SafetensorsFile read = read_safetensors(file);
  EXPECT_EQ(read.metadata, metadata);
  ASSERT_EQ(read.tensors.size(), tensors.size());
  for (const auto& [name, expected] : tensors) {
    SCOPED_TRACE(name);
    const at::Tensor& got = read.tensors.at(name);
    EXPECT_EQ(got.scalar_type(), expected.scalar_type());
    EXPECT_EQ(got.sizes(), expected.sizes());
    EXPECT_TRUE(at::equal(got, expected));
  }
}

TEST(Safetensors, WritesTheStandardByteLayout) {
  test::TempDir dir;
  const auto file = dir / "small.safetensors";
  write_safetensors(file, {{"a", at::tensor({1.0f, -2.0f})}, {"b", at::tensor({1, 2, 3}, at::kByte)}},
                    {{"format", "pt"}});

  std::string json =
      R"({"__metadata__":{"format":"pt"},)"
      R"("a":{"dtype":"F32","shape":[2],"data_offsets":[0,8]},)"
      R"("b":{"dtype":"U8","shape":[3],"data_offsets":[8,11]}})";
  json.append((8 - json.size() % 8) % 8, ' ');
  const std::string expected = hand_built(json, raw<float>({1.0f, -2.0f}) + raw<uint8_t>({1, 2, 3}));
  EXPECT_EQ(read_bytes(file), expected);
  EXPECT_EQ((read_bytes(file).size() - 11) % 8, 0u);  // header padded to 8 bytes
}

TEST(Safetensors, OrdersLargerElementsFirstSoDataIsAligned) {
  test::TempDir dir;
  const auto file = dir / "aligned.safetensors";
  write_safetensors(file, {{"a_byte", at::ones({3}, at::kByte)}, {"b_double", at::ones({2}, at::kDouble)}});
  const std::string bytes = read_bytes(file);
  const std::string json = bytes.substr(8, bytes.size() - 8 - 19);
  EXPECT_NE(json.find(R"("b_double":{"dtype":"F64","shape":[2],"data_offsets":[0,16]})"), std::string::npos) << json;
  EXPECT_NE(json.find(R"("a_byte":{"dtype":"U8","shape":[3],"data_offsets":[16,19]})"), std::string::npos) << json;
}

TEST(Safetensors, ReadsAHandBuiltFile) {
  // Keys out of data order, unpadded header, no metadata, 2-D I64.
  test::TempDir dir;
  const auto file = dir / "hand.safetensors";
  const std::string json =
      R"({"w":{"dtype":"I64","shape":[2,1],"data_offsets":[4,20]},"s":{"dtype":"I32","shape":[],"data_offsets":[0,4]}})";
  write_bytes(file, hand_built(json, raw<int32_t>({-9}) + raw<int64_t>({5, 6})));
  const SafetensorsFile read = read_safetensors(file);
  EXPECT_TRUE(read.metadata.empty());
  ASSERT_EQ(read.tensors.size(), 2u);
  EXPECT_EQ(read.tensors.at("s").dim(), 0);
  EXPECT_EQ(read.tensors.at("s").item<int32_t>(), -9);
  EXPECT_TRUE(at::equal(read.tensors.at("w"), at::tensor({5, 6}, at::kLong).view({2, 1})));
}

TEST(Safetensors, RejectsCorruptFilesNamingThem) {
  test::TempDir dir;
  const auto good = dir / "good.safetensors";
  write_safetensors(good, {{"x", at::arange(10, at::kFloat)}});
  const std::string bytes = read_bytes(good);
  const std::string ok_data = raw<float>({1, 2});

  const auto truncated = dir / "truncated.safetensors";
  write_bytes(truncated, bytes.substr(0, bytes.size() - 3));
  expect_read_error(truncated, "beyond the data");

  const auto short_header = dir / "short_header.safetensors";
  write_bytes(short_header, bytes.substr(0, 20));
  expect_read_error(short_header, "header length");

  const auto tiny = dir / "tiny.safetensors";
  write_bytes(tiny, "abc");
  expect_read_error(tiny, "too short");

  const auto bad_offsets = dir / "bad_offsets.safetensors";
  write_bytes(bad_offsets, hand_built(R"({"x":{"dtype":"F32","shape":[2],"data_offsets":[0,12]}})", ok_data));
  expect_read_error(bad_offsets, "'x'");

  const auto wrong_size = dir / "wrong_size.safetensors";
  write_bytes(wrong_size, hand_built(R"({"x":{"dtype":"F32","shape":[3],"data_offsets":[0,8]}})", ok_data));
  expect_read_error(wrong_size, "needs 12");

  const auto gap = dir / "gap.safetensors";
  write_bytes(gap, hand_built(R"({"x":{"dtype":"F32","shape":[1],"data_offsets":[4,8]}})", ok_data));
  expect_read_error(gap, "gap");

  const auto trailing = dir / "trailing.safetensors";
  write_bytes(trailing, hand_built(R"({"x":{"dtype":"F32","shape":[1],"data_offsets":[0,4]}})", ok_data));
  expect_read_error(trailing, "belong to none");

  const auto bad_json = dir / "bad_json.safetensors";
  write_bytes(bad_json, hand_built(R"({"x":{"dtype":"F32",)", ok_data));
  expect_read_error(bad_json, "malformed JSON");

  const auto bad_dtype = dir / "bad_dtype.safetensors";
  write_bytes(bad_dtype, hand_built(R"({"x":{"dtype":"F8","shape":[8],"data_offsets":[0,8]}})", ok_data));
  expect_read_error(bad_dtype, "unsupported dtype 'F8'");

  const auto negative = dir / "negative.safetensors";
  write_bytes(negative, hand_built(R"({"x":{"dtype":"F32","shape":[-2],"data_offsets":[0,8]}})", ok_data));
  expect_read_error(negative, "non-negative");

  const auto bad_metadata = dir / "bad_metadata.safetensors";
  write_bytes(bad_metadata, hand_built(R"({"__metadata__":{"n":3}})", ""));
  expect_read_error(bad_metadata, "not a string");

  expect_read_error(dir / "missing.safetensors", "cannot open");
}

TEST(Safetensors, RefusesTheReservedNameAndKeepsTheOldFileOnError) {
  test::TempDir dir;
  const auto file = dir / "ckpt.safetensors";
  write_safetensors(file, {{"x", at::ones({2})}});
  const std::string before = read_bytes(file);
  EXPECT_THROW(write_safetensors(file, {{"__metadata__", at::ones({1})}}), Error);
  EXPECT_THROW(write_safetensors(file, {{"c", at::ones({1}, at::kComplexFloat)}}), Error);
  EXPECT_EQ(read_bytes(file), before);
}

}  // namespace
}  // namespace tega::nn
