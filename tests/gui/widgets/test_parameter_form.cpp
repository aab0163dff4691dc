#include <QCheckBox>
#include <QComboBox>
#include <QDoubleSpinBox>
#include <QSignalSpy>
#include <QSpinBox>
#include <gtest/gtest.h>

#include "delineo/core/params.hpp"
#include "delineo/widgets/parameter_form.hpp"
#include "gui_test_support.hpp"

using delineo::core::ParamInfo;
using delineo::widgets::ParameterForm;

namespace {
struct SampleParams {
  double edgeWeight = 2.5;  // unitless
  double gsd = 0.5;         // m
  int iterations = 100;
  bool smooth = true;
  std::string method = "fast";

  template <class V>
  void visit(V&& v) {
    v(ParamInfo{"edge-weight", "Edge weight", "", "Weight of the edge terms", 0, 10}, edgeWeight);
    v(ParamInfo{"gsd", "Ground sample distance", "m", "Size of a pixel on the ground", 0.01, 100}, gsd);
    v(ParamInfo{"iterations", "Iterations", "", "Maximum number of iterations", 1, 10000}, iterations);
    v(ParamInfo{"smooth", "Smooth", "", "Smooth the result", 0, 1}, smooth);
    v(ParamInfo{"method", "Method", "", "Search method", 0, 0, "fast|accurate"}, method);
  }
  void validate() const { delineo::core::checkDeclaredRanges(*this); }
};
}  // namespace

TEST(ParameterForm, RoundTripsEveryFieldType) {
  ParameterForm form;
  SampleParams custom;
  custom.edgeWeight = 7.25;
  custom.gsd = 0.125;
  custom.iterations = 42;
  custom.smooth = false;
  custom.method = "accurate";
  form.setParams(custom);
  EXPECT_EQ(form.rowCount(), 5);
  SampleParams read;
  form.readInto(read);
  EXPECT_DOUBLE_EQ(read.edgeWeight, 7.25);
  EXPECT_DOUBLE_EQ(read.gsd, 0.125);
  EXPECT_EQ(read.iterations, 42);
  EXPECT_FALSE(read.smooth);
  EXPECT_EQ(read.method, "accurate");
}

TEST(ParameterForm, EditorsCarryRangeUnitTooltipAndSignalChanges) {
  ParameterForm form;
  form.setParams(SampleParams{});
  auto* gsd = qobject_cast<QDoubleSpinBox*>(form.editor("gsd"));
  ASSERT_NE(gsd, nullptr);
  EXPECT_EQ(gsd->suffix(), QStringLiteral(" m"));
  EXPECT_DOUBLE_EQ(gsd->minimum(), 0.01);
  EXPECT_DOUBLE_EQ(gsd->maximum(), 100.0);
  EXPECT_TRUE(gsd->toolTip().contains(QStringLiteral("Size of a pixel")));
  EXPECT_TRUE(gsd->toolTip().contains(QStringLiteral("Default: 0.5")));
  EXPECT_NE(qobject_cast<QSpinBox*>(form.editor("iterations")), nullptr);
  EXPECT_NE(qobject_cast<QCheckBox*>(form.editor("smooth")), nullptr);
  auto* method = qobject_cast<QComboBox*>(form.editor("method"));
  ASSERT_NE(method, nullptr);
  EXPECT_EQ(method->count(), 2);

  QSignalSpy spy(&form, &ParameterForm::changed);
  gsd->setValue(2.0);
  method->setCurrentIndex(1);
  EXPECT_EQ(spy.count(), 2);
  SampleParams read;
  form.readInto(read);
  EXPECT_DOUBLE_EQ(read.gsd, 2.0);
  EXPECT_EQ(read.method, "accurate");
  // Out-of-range input is clamped by the editor, so the struct stays valid.
  gsd->setValue(1e6);
  form.readInto(read);
  EXPECT_NO_THROW(read.validate());

  form.resize(360, 200);
  delineo::widgets::test::saveScreenshot(form, QStringLiteral("parameter_form"));
}
