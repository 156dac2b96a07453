#include "evfs/core/enum_names.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "evfs/core/error.h"

namespace evfs {
namespace {

enum class Fruit { kApple, kPear, kPlum, kFig };

constexpr EnumName<Fruit> kFruitNames[] = {
    {Fruit::kApple, "apple", "red or green"},
    {Fruit::kPear, "pear", "pear-shaped"},
    {Fruit::kPlum, "plum", "a stone fruit"},
};

TEST(EnumNames, NameOfLooksUpTheValue) {
  static_assert(NameOf(kFruitNames, Fruit::kPear)[0] == 'p', "NameOf is constexpr");
  EXPECT_STREQ(NameOf(kFruitNames, Fruit::kApple), "apple");
  EXPECT_STREQ(NameOf(kFruitNames, Fruit::kPlum), "plum");
  EXPECT_STREQ(NameOf(kFruitNames, Fruit::kFig), "");
  EXPECT_STREQ(NameOf(kFruitNames, Fruit::kFig, "unknown"), "unknown");
}

TEST(EnumNames, FindNameIsTheInverseOfNameOf) {
  for (const EnumName<Fruit>& row : kFruitNames) {
    Fruit fruit = Fruit::kFig;
    EXPECT_TRUE(FindName(kFruitNames, row.name, &fruit)) << row.name;
    EXPECT_EQ(fruit, row.value);
    EXPECT_STREQ(NameOf(kFruitNames, fruit), row.name);
  }
  Fruit fruit = Fruit::kFig;
  EXPECT_FALSE(FindName(kFruitNames, "Apple", &fruit));  // case matters
  EXPECT_FALSE(FindName(kFruitNames, "", &fruit));
  EXPECT_FALSE(FindName(kFruitNames, "apples", &fruit));
  EXPECT_EQ(fruit, Fruit::kFig);  // untouched when not found
}

TEST(EnumNames, NameListJoinsTheNamesInOrder) {
  EXPECT_EQ(NameList(kFruitNames), "apple, pear, plum");
  EXPECT_EQ(NameList(kFruitNames, ", ", " or "), "apple, pear or plum");
  EXPECT_EQ(NameList(kFruitNames, " | "), "apple | pear | plum");
  constexpr EnumName<Fruit> kOne[] = {{Fruit::kFig, "fig", ""}};
  EXPECT_EQ(NameList(kOne, ", ", " or "), "fig");
  constexpr EnumName<Fruit> kTwo[] = {{Fruit::kFig, "fig", ""}, {Fruit::kPlum, "plum", ""}};
  EXPECT_EQ(NameList(kTwo, ", ", " or "), "fig or plum");
}

TEST(EnumNames, AllValuesFollowsTheTable) {
  EXPECT_EQ(AllValues(kFruitNames),
            (std::vector<Fruit>{Fruit::kApple, Fruit::kPear, Fruit::kPlum}));
}

TEST(EnumNames, ParseNameThrowsListingTheNames) {
  EXPECT_EQ(ParseName(kFruitNames, "pear", "--fruit"), Fruit::kPear);
  try {
    ParseName(kFruitNames, "kiwi", "--fruit");
    FAIL() << "kiwi parsed";
  } catch (const InvalidArgumentError& error) {
    EXPECT_STREQ(error.what(), "--fruit must be apple, pear or plum");
  }
}

}  // namespace
}  // namespace evfs
