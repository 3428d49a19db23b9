// The .tgm transfer-model file (written by `transgi bake`, read by every
// command that renders TransGI) on untrusted bytes: ModelFileError naming the
// field, never a crash or an allocation the file cannot back.
#include <exception>

#include "fuzz_input_file.h"
#include "model/model_file.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto path = transgi_fuzz::write_input("model.tgm", data, size);
  try {
    (void)transgi::model::load_model(path);
  } catch (const std::exception&) {
  }
  return 0;
}
