#include "RenderSettingsWidget.h"

#include <QCheckBox>
#include <QComboBox>
#include <QDoubleSpinBox>
#include <QFormLayout>
#include <QSpinBox>

namespace mmrtm::viewer {
namespace {
QDoubleSpinBox* Number(double lo, double hi, double step, int decimals) {
  auto* box = new QDoubleSpinBox;
  box->setRange(lo, hi);
  box->setSingleStep(step);
  box->setDecimals(decimals);
  return box;
}
QSpinBox* Integer(int lo, int hi) {
  auto* box = new QSpinBox;
  box->setRange(lo, hi);
  return box;
}
}  // namespace

RenderSettingsWidget::RenderSettingsWidget(QWidget* parent) : QWidget(parent) {
  auto* form = new QFormLayout(this);
  samplesPerRender_ = Integer(1, 64);
  stop_ = new QComboBox;
  stop_->addItems({tr("at a number of samples"), tr("at a relative noise")});
  maximumSamples_ = Integer(1, 1 << 20);
  noiseTarget_ = Number(0.001, 1.0, 0.005, 3);
  bounces_ = Integer(0, 1024);
  shadowScale_ = Number(0.01, 1.0, 0.05, 2);
  accelerator_ = new QComboBox;
  accelerator_->addItems({tr("octree"), tr("macrocell"), tr("none (global majorant)")});
  backend_ = new QComboBox;
  backend_->addItems({tr("auto"), tr("CPU"), tr("CUDA")});
  exposure_ = Number(0.01, 100.0, 0.1, 2);
  denoising_ = new QComboBox;
  denoising_->addItems({tr("unbiased image"), tr("denoised while closer (auto)"), tr("denoised")});
  denoising_->setToolTip(tr("What the view shows. The unbiased accumulation goes on underneath either way."));
  lightAzimuth_ = Number(-180, 180, 5, 0);
  lightElevation_ = Number(-90, 90, 5, 0);
  lightIntensity_ = Number(0, 100, 0.5, 2);
  environment_ = new QCheckBox(tr("sky light"));
  form->addRow(tr("Samples per render"), samplesPerRender_);
  form->addRow(tr("Stop"), stop_);
  form->addRow(tr("Maximum samples"), maximumSamples_);
  form->addRow(tr("Noise target"), noiseTarget_);
  form->addRow(tr("Bounces"), bounces_);
  form->addRow(tr("Shadow extinction scale"), shadowScale_);
  form->addRow(tr("Accelerator"), accelerator_);
  form->addRow(tr("Backend"), backend_);
  form->addRow(tr("Exposure"), exposure_);
  form->addRow(tr("Display"), denoising_);
  form->addRow(tr("Light azimuth (deg)"), lightAzimuth_);
  form->addRow(tr("Light elevation (deg)"), lightElevation_);
  form->addRow(tr("Light intensity"), lightIntensity_);
  form->addRow(tr("Environment"), environment_);
  setSettings(RenderSettings());
  auto changed = [this] {
    if (filling_) return;
    maximumSamples_->setEnabled(stop_->currentIndex() == 0);
    noiseTarget_->setEnabled(stop_->currentIndex() == 1);
    emit settingsChanged();
  };
  for (QSpinBox* box : {samplesPerRender_, maximumSamples_, bounces_})
    connect(box, &QSpinBox::valueChanged, this, changed);
  for (QDoubleSpinBox* box : {noiseTarget_, shadowScale_, exposure_, lightAzimuth_, lightElevation_, lightIntensity_})
    connect(box, &QDoubleSpinBox::valueChanged, this, changed);
  for (QComboBox* box : {stop_, accelerator_, backend_, denoising_})
    connect(box, &QComboBox::currentIndexChanged, this, changed);
  connect(environment_, &QCheckBox::toggled, this, changed);
}

void RenderSettingsWidget::setSettings(const RenderSettings& s) {
  filling_ = true;
  samplesPerRender_->setValue(s.samplesPerRender);
  stop_->setCurrentIndex(s.stopAtNoise ? 1 : 0);
  maximumSamples_->setValue(s.maximumSamples);
  maximumSamples_->setEnabled(!s.stopAtNoise);
  noiseTarget_->setValue(s.noiseTarget);
  noiseTarget_->setEnabled(s.stopAtNoise);
  bounces_->setValue(s.bounces);
  shadowScale_->setValue(s.shadowScale);
  accelerator_->setCurrentIndex(s.accelerator);
  backend_->setCurrentIndex(s.backend);
  exposure_->setValue(s.exposure);
  denoising_->setCurrentIndex(s.denoising);
  lightAzimuth_->setValue(s.lightAzimuth);
  lightElevation_->setValue(s.lightElevation);
  lightIntensity_->setValue(s.lightIntensity);
  environment_->setChecked(s.environment);
  filling_ = false;
}

RenderSettings RenderSettingsWidget::settings() const {
  RenderSettings s;
  s.samplesPerRender = samplesPerRender_->value();
  s.stopAtNoise = stop_->currentIndex() == 1;
  s.maximumSamples = maximumSamples_->value();
  s.noiseTarget = noiseTarget_->value();
  s.bounces = bounces_->value();
  s.shadowScale = shadowScale_->value();
  s.accelerator = accelerator_->currentIndex();
  s.backend = backend_->currentIndex();
  s.exposure = exposure_->value();
  s.denoising = denoising_->currentIndex();
  s.lightAzimuth = lightAzimuth_->value();
  s.lightElevation = lightElevation_->value();
  s.lightIntensity = lightIntensity_->value();
  s.environment = environment_->isChecked();
  return s;
}

}  // namespace mmrtm::viewer
