#include "experiments/study/study_table.hpp"

#include "meshes/atomic_file.hpp"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <stdexcept>
#include <string_view>
#include <utility>

namespace kerf {

namespace {
/// "name [unit]", or "name" without a unit.
std::string header(const StudyTable::Column& c) {
  std::string h = c.name;
  if (!c.unit.empty()) {
    h += " [";
    h += c.unit;
    h += ']';
  }
  return h;
}

/// LaTeX for the non-ASCII characters kerf's tables use (units, notes), so that the table
/// compiles with pdflatex's default set-up (OT1, no inputenc declarations needed).
constexpr std::pair<const char*, const char*> latex_unicode[] = {
    {"µ", "\\textmu{}"},         {"×", "\\texttimes{}"},          {"≤", "\\ensuremath{\\le}"},
    {"≥", "\\ensuremath{\\ge}"}, {"→", "\\ensuremath{\\to}"},    {"–", "--"},
    {"—", "---"},                 {"φ", "\\ensuremath{\\varphi}"}, {"ε", "\\ensuremath{\\varepsilon}"},
    {"δ", "\\ensuremath{\\delta}"}, {"σ", "\\ensuremath{\\sigma}"}, {"ν", "\\ensuremath{\\nu}"},
    {"η", "\\ensuremath{\\eta}"},   {"μ", "\\ensuremath{\\mu}"},    {"Δ", "\\ensuremath{\\Delta}"},
    {"±", "\\ensuremath{\\pm}"},    {"²", "\\textsuperscript{2}"}, {"°", "\\textdegree{}"},
    {"…", "\\ldots{}"},           {"∞", "\\ensuremath{\\infty}"},  {"−", "\\ensuremath{-}"},
};

std::string latex_escape(const std::string& s) {
  std::string out;
  for (std::size_t k = 0; k < s.size(); ++k) {
    const char ch = s[k];
    if (static_cast<unsigned char>(ch) >= 0x80) {
      bool mapped = false;
      for (const auto& [utf8, latex] : latex_unicode) {
        const std::string_view u(utf8);
        if (s.compare(k, u.size(), u) == 0) {
          out += latex;
          k += u.size() - 1;
          mapped = true;
          break;
        }
      }
      if (!mapped) out += ch;
      continue;
    }
    switch (ch) {
    case '&': case '%': case '$': case '#': case '_': case '{': case '}': out += '\\'; out += ch; break;
    case '~': out += "\\textasciitilde{}"; break;
    case '^': out += "\\textasciicircum{}"; break;
    case '\\': out += "\\textbackslash{}"; break;
    case '|': out += "\\textbar{}"; break; // OT1 sets "|" as an em dash
    case '<': out += "\\textless{}"; break;
    case '>': out += "\\textgreater{}"; break;
    default: out += ch;
    }
  }
  return out;
}

/// A Markdown cell: a "|" in the text would end the cell ("RMS |F|").
std::string markdown_cell(const std::string& s) {
  std::string out;
  for (char ch : s) out += ch == '|' ? std::string("\\|") : std::string(1, ch);
  return out;
}

std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string out = "\"";
  for (char ch : s) out += ch == '"' ? std::string("\"\"") : std::string(1, ch);
  return out + "\"";
}
} // namespace

StudyTable::StudyTable(std::vector<Column> columns) : m_columns(std::move(columns)) {
  if (m_columns.empty()) throw std::invalid_argument("study table: no columns");
}

void StudyTable::add_row(std::vector<Cell> row) {
  if (row.size() != m_columns.size())
    throw std::invalid_argument("study table: a row has " + std::to_string(row.size()) + " cells for " +
                                std::to_string(m_columns.size()) + " columns");
  m_rows.push_back(std::move(row));
}

std::string StudyTable::shown(std::size_t column, const Cell& cell) const {
  if (const auto* text = std::get_if<std::string>(&cell)) return *text;
  const auto& number = std::get<std::optional<double>>(cell);
  if (!number) return "–";
  const double v = *number * m_columns[column].scale;
  if (!std::isfinite(v)) return std::isnan(v) ? "NaN" : (v > 0 ? "∞" : "-∞");
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*g", m_columns[column].significant_digits, v);
  return buffer;
}

bool StudyTable::numeric(std::size_t column) const {
  for (const auto& row : m_rows)
    if (std::holds_alternative<std::optional<double>>(row[column])) return true;
  return false;
}

std::string StudyTable::markdown() const {
  std::string out = m_caption.empty() ? "|" : m_caption + "\n\n|";
  for (const Column& c : m_columns) {
    out += ' ';
    out += markdown_cell(header(c));
    out += " |";
  }
  out += "\n|";
  for (std::size_t c = 0; c < m_columns.size(); ++c) out += numeric(c) ? "---:|" : "---|";
  out += "\n";
  for (const auto& row : m_rows) {
    out += "|";
    for (std::size_t c = 0; c < row.size(); ++c) {
      out += ' ';
      out += markdown_cell(shown(c, row[c]));
      out += " |";
    }
    out += "\n";
  }
  return out;
}


std::string StudyTable::latex() const {
  std::string spec;
  for (std::size_t c = 0; c < m_columns.size(); ++c) spec += numeric(c) ? "r" : "l";
  std::string out = "\\begin{tabular}{" + spec + "}\n\\toprule\n";
  for (std::size_t c = 0; c < m_columns.size(); ++c) {
    if (c) out += " & ";
    out += latex_escape(header(m_columns[c]));
  }
  out += " \\\\\n\\midrule\n";
  for (std::size_t r = 0; r < m_rows.size(); ++r) {
    const auto& row = m_rows[r];
    const bool continues_group = m_grouped && r > 0 && shown(0, row[0]) == shown(0, m_rows[r - 1][0]);
    if (m_grouped && r > 0 && !continues_group) out += "\\midrule\n";
    for (std::size_t c = 0; c < row.size(); ++c) {
      const std::string cell = c == 0 && continues_group ? std::string() : shown(c, row[c]);
      if (c) out += " & ";
      out += cell == "–" ? std::string("--") : latex_escape(cell);
    }
    out += " \\\\\n";
  }
  out += "\\bottomrule\n";
  if (!m_caption.empty())
    out += "\\multicolumn{" + std::to_string(m_columns.size()) + "}{l}{\\footnotesize " + latex_escape(m_caption) + "} \\\\\n";
  return out + "\\end{tabular}\n";
}

std::string StudyTable::csv() const {
  std::string out;
  for (std::size_t c = 0; c < m_columns.size(); ++c) {
    if (c) out += ',';
    out += csv_field(header(m_columns[c]));
  }
  out += "\n";
  for (const auto& row : m_rows) {
    for (std::size_t c = 0; c < row.size(); ++c) {
      if (c) out += ",";
      if (const auto* text = std::get_if<std::string>(&row[c])) {
        out += csv_field(*text);
      } else if (const auto& number = std::get<std::optional<double>>(row[c])) {
        char buffer[64];
        std::snprintf(buffer, sizeof buffer, "%.17g", *number * m_columns[c].scale);
        out += buffer;
      }
    }
    out += "\n";
  }
  return out;
}

void StudyTable::write(const std::filesystem::path& directory, const std::string& name) const {
  const std::pair<const char*, std::string> forms[] = {{".md", markdown()}, {".tex", latex()}, {".csv", csv()}};
  for (const auto& [extension, text] : forms)
    write_atomically(directory / (name + extension), [&](const std::filesystem::path& tmp) {
      std::ofstream out(tmp, std::ios::binary);
      out << text;
      out.flush();
      if (!out) throw std::runtime_error((directory / (name + extension)).string() + ": write failed");
    });
}

} // namespace kerf
