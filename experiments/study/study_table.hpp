#pragma once
// A study's results as a table, written as Markdown, LaTeX (booktabs) and CSV — the three forms an
// author needs: to read, to paste into a paper, and to plot or reprocess.

#include <filesystem>
#include <optional>
#include <variant>
#include <string>
#include <vector>

namespace kerf {

/// A rectangular table: a header and rows of cells. A cell is text or a number shown with a
/// fixed number of significant digits; an empty optional number is shown as "–" (not measured).
class StudyTable {
public:
  struct Column {
    std::string name;       ///< header text, e.g. "RMS force error"
    std::string unit;       ///< e.g. "%", "µs"; empty for none
    int significant_digits = 3;
    double scale = 1.0;     ///< value shown = stored value × scale (e.g. 100 for %, 1e6 for µs)
  };
  using Cell = std::variant<std::string, std::optional<double>>;

  explicit StudyTable(std::vector<Column> columns);

  /// Appends a row; its size must equal the column count (std::invalid_argument otherwise).
  void add_row(std::vector<Cell> row);

  /// A line that goes with the table (e.g. the machine the costs were measured on): Markdown
  /// prints it above the table (so that the file still ends with the table's last row), LaTeX as
  /// a last full-width row under \bottomrule; CSV has no place for it (RFC 4180 has no comments)
  /// and leaves it out.
  void set_caption(std::string text) { m_caption = std::move(text); }
  [[nodiscard]] const std::string& caption() const { return m_caption; }
  /// Rows are grouped by their first column (the study's scenes) in the LaTeX form.
  void group_by_first_column(bool grouped) { m_grouped = grouped; }

  [[nodiscard]] const std::vector<Column>& columns() const { return m_columns; }
  [[nodiscard]] std::size_t row_count() const { return m_rows.size(); }

  /// GitHub-flavoured Markdown, numbers right-aligned.
  [[nodiscard]] std::string markdown() const;
  /// A LaTeX tabular with \toprule/\midrule/\bottomrule (booktabs); text escaped for LaTeX. With
  /// group_by_first_column: a \midrule between groups of rows with the same first cell, that cell
  /// shown on the group's first row only.
  [[nodiscard]] std::string latex() const;
  /// RFC 4180 CSV at full precision (17 digits) in the column's unit, header "name [unit]"; an
  /// unmeasured number is an empty field.
  [[nodiscard]] std::string csv() const;

  /// Writes NAME.md, NAME.tex and NAME.csv into `directory`, each atomically.
  void write(const std::filesystem::path& directory, const std::string& name) const;

private:
  [[nodiscard]] std::string shown(std::size_t column, const Cell& cell) const;
  /// A column holding at least one number (right-aligned), else text.
  [[nodiscard]] bool numeric(std::size_t column) const;
  std::string m_caption;
  bool m_grouped = false;
  std::vector<Column> m_columns;
  std::vector<std::vector<Cell>> m_rows;
};

} // namespace kerf
