// A minimal JSON writer for summary files: objects, keys and scalar fields, with commas and
// string escaping handled. Doubles are written with enough digits to read back exactly.
#ifndef EVFS_APP_JSON_WRITER_H_
#define EVFS_APP_JSON_WRITER_H_

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

namespace evfs {

class JsonWriter {
 public:
  JsonWriter& BeginObject() {
    Separate();
    text_ += '{';
    first_.push_back(true);
    return *this;
  }
  JsonWriter& EndObject() {
    first_.pop_back();
    text_ += '}';
    return *this;
  }
  JsonWriter& BeginArray() {
    Separate();
    text_ += '[';
    first_.push_back(true);
    return *this;
  }
  JsonWriter& EndArray() {
    first_.pop_back();
    text_ += ']';
    return *this;
  }
  /// Starts a member; the next Begin/Value call writes its value.
  JsonWriter& Key(const std::string& key) {
    Separate();
    AppendString(key);
    text_ += ": ";
    after_key_ = true;
    return *this;
  }
  void Field(const std::string& key, const std::string& value) { Key(key).String(value); }
  void Field(const std::string& key, const char* value) { Key(key).String(value); }
  void Field(const std::string& key, bool value) { Key(key).Raw(value ? "true" : "false"); }
  void Field(const std::string& key, int value) { Key(key).Raw(std::to_string(value)); }
  void Field(const std::string& key, int64_t value) { Key(key).Raw(std::to_string(value)); }
  void Field(const std::string& key, double value) { Key(key).Number(value); }
  /// A number as the next element of the open array.
  void Element(double value) { Number(value); }

  const std::string& str() const { return text_; }

 private:
  void Separate() {
    if (after_key_) {
      after_key_ = false;
      return;
    }
    if (!first_.empty()) {
      if (!first_.back()) text_ += ", ";
      first_.back() = false;
    }
  }
  void Raw(const std::string& value) {
    Separate();
    text_ += value;
  }
  void Number(double value) {
    if (!std::isfinite(value)) return Raw("null");  // JSON has no inf/nan
    char buffer[32];
    std::snprintf(buffer, sizeof(buffer), "%.10g", value);
    Raw(buffer);
  }
  void String(const std::string& value) {
    Separate();
    AppendString(value);
  }
  void AppendString(const std::string& value) {
    text_ += '"';
    for (const char c : value) {
      switch (c) {
        case '"':
          text_ += "\\\"";
          break;
        case '\\':
          text_ += "\\\\";
          break;
        case '\n':
          text_ += "\\n";
          break;
        case '\t':
          text_ += "\\t";
          break;
        case '\r':
          text_ += "\\r";
          break;
        default:
          if (static_cast<unsigned char>(c) < 0x20) {
            char escaped[8];
            std::snprintf(escaped, sizeof(escaped), "\\u%04x", c);
            text_ += escaped;
          } else {
            text_ += c;
          }
      }
    }
    text_ += '"';
  }

  std::string text_;
  std::vector<bool> first_;
  bool after_key_ = false;
};

}  // namespace evfs

#endif  // EVFS_APP_JSON_WRITER_H_
