// Tests of ModelText: the model's text shown to the console, never changed while held.
#include <algorithm>
#include <string>
#include <string_view>

#include "firmware/telemetry/model_text.h"

#include "CppUTest/TestHarness.h"

using boticelli::firmware::ModelText;

namespace {
ModelText g_text;  // two 64 KB buffers: static

void publish(const std::string& text) {
  std::copy(text.begin(), text.end(), g_text.back().begin());
  g_text.publish(text.size());
}
}  // namespace

TEST_GROUP(ModelText){void setup() override{g_text.clear();
}
}
;

TEST(ModelText, HasNoTextUntilOneIsPublished) {
  CHECK(g_text.current().empty());
}

TEST(ModelText, ShowsAPublishedTextAtOnceWhenNobodyHoldsIt) {
  publish("first");
  STRCMP_EQUAL("first", std::string(g_text.current()).c_str());
  publish("second");
  STRCMP_EQUAL("second", std::string(g_text.current()).c_str());
}

TEST(ModelText, KeepsAHeldTextUnchangedAndShowsTheNewestOnceReleased) {
  publish("first model");
  const std::string_view held = g_text.hold();
  publish("second model");
  publish("third");  // written into the same free buffer, not the held one
  STRCMP_EQUAL("first model", std::string(held).c_str());
  STRCMP_EQUAL("first model", std::string(g_text.current()).c_str());
  g_text.release();
  STRCMP_EQUAL("third", std::string(g_text.current()).c_str());
}

TEST(ModelText, WritesANewTextNeverIntoTheHeldBuffer) {
  publish("aaaa");
  const std::string_view held = g_text.hold();
  CHECK(g_text.back().data() != held.data());
  g_text.release();
  CHECK(g_text.back().data() != g_text.current().data());
}
