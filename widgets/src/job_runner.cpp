#include "delineo/widgets/job_runner.hpp"

#include "delineo/widgets/stage_text.hpp"

#include <QCoreApplication>
#include <QElapsedTimer>
#include <QFutureWatcher>
#include <QHBoxLayout>
#include <QLabel>
#include <QProgressBar>
#include <QStyle>
#include <QThread>
#include <QToolButton>
#include <QtConcurrent/QtConcurrentRun>
#include <exception>
#include <new>

namespace delineo::widgets {

struct JobRunner::Job {
  JobId id = 0;
  QString name;
  QString key;
  std::function<void(core::Progress&)> work;
  std::function<void()> deliver;
  core::Progress progress;
  QFuture<void> future;
  QFutureWatcher<void>* watcher = nullptr;
  // Written by the worker, read on the GUI thread only after the future finished.
  bool failed = false;
  core::ErrorCode errorCode = core::ErrorCode::ProcessingFailed;
  QString errorMessage;
  // Last values forwarded to the GUI.
  double shownFraction = -1.0;
  QString shownStage;
};

JobRunner::JobRunner(QObject* parent) : QObject(parent) {
  qRegisterMetaType<delineo::widgets::JobId>("delineo::widgets::JobId");
  qRegisterMetaType<delineo::core::ErrorCode>("delineo::core::ErrorCode");
  qRegisterMetaType<delineo::widgets::JobOutcome>("delineo::widgets::JobOutcome");
  pollTimer_.setInterval(50);  // progress forwarded at most at 20 Hz
  connect(&pollTimer_, &QTimer::timeout, this, &JobRunner::pollProgress);
}

JobRunner::~JobRunner() {
  for (const auto& job : std::as_const(jobs_)) job->progress.cancel();
  for (const auto& job : std::as_const(jobs_)) {
    job->future.waitForFinished();
    // The watcher would otherwise deliver a queued "finished" to a half-destroyed runner.
    job->watcher->disconnect(this);
  }
}

JobId JobRunner::start(const QString& name, const QString& key,
                       std::function<void(core::Progress&)> work, std::function<void()> deliver) {
  if (!key.isEmpty()) {
    for (const auto& other : std::as_const(jobs_)) {
      if (other->key == key) other->progress.cancel();
    }
  }
  auto job = std::make_shared<Job>();
  job->id = nextId_++;
  job->name = name;
  job->key = key;
  job->work = std::move(work);
  job->deliver = std::move(deliver);
  job->watcher = new QFutureWatcher<void>(this);
  const JobId id = job->id;
  connect(job->watcher, &QFutureWatcher<void>::finished, this, [this, id] { onWorkerDone(id); });
  jobs_.insert(id, job);

  // The worker holds only the job; it never touches the runner.
  job->future = QtConcurrent::run([job] {
    if (job->progress.canceled()) return;  // canceled before it could start
    try {
      job->work(job->progress);
    } catch (const core::Error& error) {
      job->failed = true;
      job->errorCode = error.code();
      // The code is said apart (its translated sentence): the message is the detail and its file.
      job->errorMessage = QString::fromStdString(error.path().empty() ? error.detail() : error.path() + ": " + error.detail());
    } catch (const std::bad_alloc&) {
      job->failed = true;
      job->errorMessage = QStringLiteral("out of memory");
    } catch (const std::exception& error) {
      job->failed = true;
      job->errorMessage = QString::fromStdString(error.what());
    } catch (...) {
      job->failed = true;
      job->errorMessage = QStringLiteral("unknown exception");
    }
  });
  job->watcher->setFuture(job->future);

  if (!pollTimer_.isActive()) pollTimer_.start();
  emit started(id, name);
  emit activeCountChanged(activeCount());
  return id;
}

void JobRunner::onWorkerDone(JobId id) {
  auto it = jobs_.find(id);
  if (it == jobs_.end()) return;
  std::shared_ptr<Job> job = it.value();
  jobs_.erase(it);
  job->watcher->deleteLater();
  if (jobs_.isEmpty()) pollTimer_.stop();

  JobOutcome outcome = JobOutcome::Finished;
  if (job->progress.canceled()) {
    outcome = JobOutcome::Canceled;  // even a failure after cancel is just a cancel
  } else if (job->failed) {
    outcome = JobOutcome::Failed;
  }
  switch (outcome) {
    case JobOutcome::Finished:
      if (job->shownFraction < 1.0) emit progressChanged(id, 1.0, job->shownStage);
      if (job->deliver) job->deliver();
      emit finished(id);
      break;
    case JobOutcome::Canceled: emit canceled(id); break;
    case JobOutcome::Failed: emit failed(id, job->errorCode, job->errorMessage); break;
  }
  emit ended(id, outcome);
  emit activeCountChanged(activeCount());
}

void JobRunner::pollProgress() {
  // Copy: a slot connected to progressChanged may start or cancel jobs.
  const auto jobs = jobs_.values();
  for (const auto& job : jobs) {
    const double fraction = job->progress.fraction();
    const QString stage = stageText(job->progress.stageInfo());
    if (fraction != job->shownFraction || stage != job->shownStage) {
      job->shownFraction = fraction;
      job->shownStage = stage;
      emit progressChanged(job->id, fraction, stage);
    }
  }
}

void JobRunner::cancel(JobId id) {
  auto it = jobs_.find(id);
  if (it != jobs_.end()) it.value()->progress.cancel();
}

void JobRunner::cancelAll() {
  for (const auto& job : std::as_const(jobs_)) job->progress.cancel();
}

bool JobRunner::isActive(JobId id) const { return jobs_.contains(id); }

QString JobRunner::jobName(JobId id) const {
  auto it = jobs_.find(id);
  return it == jobs_.end() ? QString() : it.value()->name;
}

double JobRunner::jobFraction(JobId id) const {
  auto it = jobs_.find(id);
  return it == jobs_.end() ? 0.0 : std::max(0.0, it.value()->shownFraction);
}

QString JobRunner::jobStage(JobId id) const {
  auto it = jobs_.find(id);
  return it == jobs_.end() ? QString() : it.value()->shownStage;
}

bool JobRunner::waitForIdle(int msec) {
  QElapsedTimer timer;
  timer.start();
  while (!jobs_.isEmpty() && timer.elapsed() < msec) {
    QCoreApplication::processEvents(QEventLoop::AllEvents, 10);
    if (!jobs_.isEmpty()) QThread::msleep(2);
  }
  return jobs_.isEmpty();
}

// ---------------------------------------------------------------------------------------------

JobProgressWidget::JobProgressWidget(JobRunner* runner, QWidget* parent)
    : QWidget(parent),
      runner_(runner),
      bar_(new QProgressBar(this)),
      stage_(new QLabel(this)),
      cancel_(new QToolButton(this)) {
  auto* layout = new QHBoxLayout(this);
  layout->setContentsMargins(0, 0, 0, 0);
  layout->addWidget(stage_, 1);
  layout->addWidget(bar_, 2);
  layout->addWidget(cancel_);
  bar_->setRange(0, 1000);
  bar_->setTextVisible(true);
  cancel_->setText(tr("Cancel"));
  cancel_->setToolTip(tr("Cancel the running job"));
  cancel_->setIcon(style()->standardIcon(QStyle::SP_DialogCancelButton));
  cancel_->setToolButtonStyle(Qt::ToolButtonTextBesideIcon);
  connect(cancel_, &QToolButton::clicked, this, [this] {
    if (job_ != 0) {
      runner_->cancel(job_);
      stage_->setText(tr("Canceling…"));
      cancel_->setEnabled(false);
    }
  });
  connect(runner_, &JobRunner::started, this, [this](JobId id, const QString& name) {
    if (!followLatest_) return;
    job_ = id;
    stage_->setText(name);
    bar_->setValue(0);
    bar_->setFormat(QStringLiteral("%p%"));
    cancel_->setEnabled(true);
  });
  connect(runner_, &JobRunner::progressChanged, this,
          [this](JobId id, double fraction, const QString& stage) {
            if (id != job_) return;
            bar_->setValue(static_cast<int>(fraction * 1000.0 + 0.5));
            const QString name = runner_->jobName(id);
            // The separator is translatable: French puts a space before the colon.
            stage_->setText(stage.isEmpty() ? name : tr("%1: %2", "job name: stage").arg(name, stage));
          });
  connect(runner_, &JobRunner::ended, this, [this](JobId id, JobOutcome) {
    if (id != job_) return;
    job_ = 0;
    showIdle();
  });
  showIdle();
}

void JobProgressWidget::setJob(JobId id) {
  followLatest_ = id == 0;
  job_ = id;
  if (id == 0 || !runner_->isActive(id)) {
    job_ = 0;
    showIdle();
    return;
  }
  stage_->setText(runner_->jobName(id));
  bar_->setValue(static_cast<int>(runner_->jobFraction(id) * 1000.0 + 0.5));
  cancel_->setEnabled(true);
}

void JobProgressWidget::showIdle() {
  // Another job may still be running: follow it when following the latest.
  stage_->setText(tr("Idle"));
  bar_->setValue(0);
  bar_->setFormat(QString());
  cancel_->setEnabled(false);
}

}  // namespace delineo::widgets
