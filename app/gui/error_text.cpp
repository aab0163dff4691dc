#include "error_text.hpp"

#include <QCoreApplication>
#include <QFileInfo>

namespace delineo::gui {

QString errorSentence(core::ErrorCode code, const QString& path) {
  const QString file = path.isEmpty() ? QCoreApplication::translate("ErrorText", "the file") : QFileInfo(path).fileName();
  switch (code) {
    case core::ErrorCode::InvalidParameter: return QCoreApplication::translate("ErrorText", "A parameter value is not valid.");
    case core::ErrorCode::FileNotFound: return QCoreApplication::translate("ErrorText", "The file %1 does not exist.").arg(file);
    case core::ErrorCode::UnreadableFile:
      return QCoreApplication::translate("ErrorText", "The file %1 cannot be read: it is damaged or not in a supported format.").arg(file);
    case core::ErrorCode::UnsupportedInput: return QCoreApplication::translate("ErrorText", "The file %1 is not supported.").arg(file);
    case core::ErrorCode::MismatchedInputs: return QCoreApplication::translate("ErrorText", "The input files do not match each other.");
    case core::ErrorCode::WriteFailed: return QCoreApplication::translate("ErrorText", "Delineo could not write %1.").arg(file);
    case core::ErrorCode::UnusableOutput:
      return QCoreApplication::translate("ErrorText", "Delineo does not write %1: choose another file.").arg(file);
    case core::ErrorCode::ProcessingFailed: return QCoreApplication::translate("ErrorText", "The processing failed.");
  }
  return QCoreApplication::translate("ErrorText", "An unexpected error occurred.");
}

QString errorMessage(const core::Error& error) {
  const QString path = QString::fromStdString(error.path());
  QString text = errorSentence(error.code(), path);
  text += QStringLiteral("\n\n") + QString::fromStdString(error.detail());
  if (!path.isEmpty()) text += QStringLiteral("\n") + QCoreApplication::translate("ErrorText", "File: %1").arg(path);
  return text;
}

}  // namespace delineo::gui
