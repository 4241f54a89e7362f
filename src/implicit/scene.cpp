// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/implicit/scene.h"

#include "pointform/core/error.h"
#include "pointform/implicit/operators.h"
#include "pointform/implicit/primitives.h"
#include "pointform/implicit/transform.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstddef>
#include <fstream>
#include <map>
#include <numbers>
#include <optional>
#include <sstream>
#include <system_error>
#include <utility>

namespace pointform {
namespace {

using FieldPtr = std::shared_ptr<const Field>;

/// How deep calls and vectors may nest in a scene's text, and operators and transforms in its
/// field (through bindings too): deeper scenes are refused, so that parsing, checking, building,
/// evaluating and destroying one never recurses deeper than this.
constexpr int max_nesting = 256;

// ---------------------------------------------------------------------------------------------
// Diagnostics

struct Pos
{
    int line = 1;
    int column = 1;
};

std::string to_string(Pos pos)
{
    return std::to_string(pos.line) + ":" + std::to_string(pos.column);
}

/// Levenshtein distance, for "did you mean".
std::size_t edit_distance(std::string_view a, std::string_view b)
{
    std::vector<std::size_t> row(b.size() + 1);
    for (std::size_t j = 0; j <= b.size(); ++j)
    {
        row[j] = j;
    }
    for (std::size_t i = 1; i <= a.size(); ++i)
    {
        std::size_t diagonal = row[0];
        row[0] = i;
        for (std::size_t j = 1; j <= b.size(); ++j)
        {
            const std::size_t substitution = diagonal + (a[i - 1] == b[j - 1] ? 0 : 1);
            diagonal = row[j];
            row[j] = std::min({row[j] + 1, row[j - 1] + 1, substitution});
        }
    }
    return row[b.size()];
}

/// The closest candidate, if it is close enough to be a likely typo.
std::optional<std::string> closest(std::string_view word,
                                   const std::vector<std::string>& candidates)
{
    std::optional<std::string> best;
    std::size_t best_distance = 0;
    // A word of three letters or more that starts a candidate: "hyper" → "hyperbolic".
    if (word.size() >= 3)
    {
        for (const std::string& candidate : candidates)
        {
            if (candidate.size() > word.size() && candidate.starts_with(word))
            {
                return candidate;
            }
        }
    }
    for (const std::string& candidate : candidates)
    {
        const std::size_t d = edit_distance(word, candidate);
        if (!best || d < best_distance)
        {
            best = candidate;
            best_distance = d;
        }
    }
    const std::size_t allowed =
        std::max<std::size_t>(1, std::min(word.size(), std::size_t{12}) / 3);
    if (best && best_distance <= allowed && best_distance < word.size())
    {
        return best;
    }
    return std::nullopt;
}

std::string did_you_mean(std::string_view word, const std::vector<std::string>& candidates)
{
    const auto best = closest(word, candidates);
    return best ? "; did you mean '" + *best + "'?" : "";
}

// ---------------------------------------------------------------------------------------------
// Lexer

enum class Tok
{
    Name,
    Number,
    String,
    LParen,
    RParen,
    LBracket,
    RBracket,
    Comma,
    Equals,
    Separator, // a newline outside brackets, or ';'
    End,
};

struct Token
{
    Tok kind = Tok::End;
    Pos pos;
    std::string text; // as written (a string's decoded content for Tok::String)
    double number = 0.0;
};

std::string describe(const Token& token)
{
    switch (token.kind)
    {
        case Tok::Name:
        case Tok::Number:
            return "'" + token.text + "'";
        case Tok::String:
            return "the string \"" + token.text + "\"";
        case Tok::Separator:
            return token.text == ";" ? "';'" : "end of line";
        case Tok::End:
            return "end of input";
        default:
            return "'" + token.text + "'";
    }
}

class Lexer
{
public:
    Lexer(std::string_view text, const std::string& source) : text_(text), source_(source) {}

    std::vector<Token> tokenize()
    {
        std::vector<Token> tokens;
        for (;;)
        {
            skip_blanks_and_comments();
            const Pos pos = pos_;
            if (at_end())
            {
                tokens.push_back({.kind = Tok::End, .pos = pos});
                return tokens;
            }
            const char c = text_[i_];
            if (c == '\n' || c == ';')
            {
                advance();
                if (depth_ == 0)
                {
                    tokens.push_back(
                        {.kind = Tok::Separator, .pos = pos, .text = c == ';' ? ";" : "\n"});
                }
                continue;
            }
            if (is_name_start(c))
            {
                tokens.push_back(lex_name());
                continue;
            }
            if (is_digit(c) || c == '.' || c == '-' || c == '+')
            {
                tokens.push_back(lex_number());
                continue;
            }
            if (c == '"')
            {
                tokens.push_back(lex_string());
                continue;
            }
            Tok kind = Tok::End;
            switch (c)
            {
                case '(':
                    kind = Tok::LParen;
                    ++depth_;
                    break;
                case '[':
                    kind = Tok::LBracket;
                    ++depth_;
                    break;
                case ')':
                    kind = Tok::RParen;
                    depth_ = std::max(depth_ - 1, 0);
                    break;
                case ']':
                    kind = Tok::RBracket;
                    depth_ = std::max(depth_ - 1, 0);
                    break;
                case ',':
                    kind = Tok::Comma;
                    break;
                case '=':
                    kind = Tok::Equals;
                    break;
                default:
                    fail(pos, "unexpected character '" + current_character() + "'");
            }
            advance();
            tokens.push_back({.kind = kind, .pos = pos, .text = std::string(1, c)});
        }
    }

private:
    static bool is_digit(char c) { return c >= '0' && c <= '9'; }
    static bool is_name_start(char c)
    {
        return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_';
    }
    static bool is_name_char(char c) { return is_name_start(c) || is_digit(c); }

    [[nodiscard]] bool at_end() const { return i_ >= text_.size(); }
    [[nodiscard]] char peek(std::size_t ahead = 0) const
    {
        return i_ + ahead < text_.size() ? text_[i_ + ahead] : '\0';
    }

    /// Moves one byte on; columns count code points (UTF-8 continuation bytes do not advance).
    void advance()
    {
        const auto byte = static_cast<unsigned char>(text_[i_]);
        ++i_;
        if (byte == '\n')
        {
            ++pos_.line;
            pos_.column = 1;
        }
        else if ((byte & 0xC0U) != 0x80U)
        {
            ++pos_.column;
        }
    }

    /// The whole UTF-8 sequence at the cursor, for messages.
    [[nodiscard]] std::string current_character() const
    {
        std::size_t end = i_ + 1;
        while (end < text_.size() && (static_cast<unsigned char>(text_[end]) & 0xC0U) == 0x80U)
        {
            ++end;
        }
        return std::string(text_.substr(i_, end - i_));
    }

    [[noreturn]] void fail(Pos pos, const std::string& message) const
    {
        throw InvalidInput(source_ + ":" + to_string(pos) + ": " + message);
    }

    void skip_blanks_and_comments()
    {
        while (!at_end())
        {
            const char c = text_[i_];
            if (c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v')
            {
                advance();
            }
            else if (c == '#')
            {
                while (!at_end() && text_[i_] != '\n')
                {
                    advance();
                }
            }
            else
            {
                return;
            }
        }
    }

    Token lex_name()
    {
        Token token{.kind = Tok::Name, .pos = pos_};
        const std::size_t start = i_;
        while (!at_end() && is_name_char(text_[i_]))
        {
            advance();
        }
        token.text = std::string(text_.substr(start, i_ - start));
        return token;
    }

    void digits()
    {
        while (!at_end() && is_digit(text_[i_]))
        {
            advance();
        }
    }

    Token lex_number()
    {
        Token token{.kind = Tok::Number, .pos = pos_};
        const std::size_t start = i_;
        if (peek() == '-' || peek() == '+')
        {
            const char sign = peek();
            if (!is_digit(peek(1)) && !(peek(1) == '.' && is_digit(peek(2))))
            {
                fail(pos_, std::string("expected a number after '") + sign +
                               "' (the language has no arithmetic; write the value)");
            }
            advance();
        }
        if (peek() == '.' && !is_digit(peek(1)))
        {
            fail(pos_, "expected a digit after '.'");
        }
        digits();
        if (peek() == '.')
        {
            advance();
            digits();
        }
        if (peek() == 'e' || peek() == 'E')
        {
            const Pos exponent = pos_;
            advance();
            if (peek() == '-' || peek() == '+')
            {
                advance();
            }
            if (!is_digit(peek()))
            {
                fail(exponent, "expected the digits of an exponent after '" +
                                   std::string(text_.substr(start, i_ - start)) + "'");
            }
            digits();
        }
        token.text = std::string(text_.substr(start, i_ - start));
        // from_chars takes no leading '+'.
        const std::size_t skip = token.text[0] == '+' ? 1 : 0;
        const char* first = token.text.data() + skip;
        const char* last = token.text.data() + token.text.size();
        const auto [end, error] = std::from_chars(first, last, token.number);
        if (error == std::errc::result_out_of_range || !std::isfinite(token.number))
        {
            fail(token.pos, "the number '" + token.text + "' is out of range");
        }
        if (error != std::errc() || end != last)
        {
            fail(token.pos, "malformed number '" + token.text + "'");
        }
        return token;
    }

    Token lex_string()
    {
        Token token{.kind = Tok::String, .pos = pos_};
        advance(); // opening quote
        for (;;)
        {
            if (at_end() || peek() == '\n')
            {
                fail(token.pos, "unterminated string: expected a closing '\"' before " +
                                    std::string(at_end() ? "end of input" : "end of line"));
            }
            const char c = peek();
            if (c == '"')
            {
                advance();
                return token;
            }
            if (c == '\\' && (peek(1) == '"' || peek(1) == '\\'))
            {
                advance();
            }
            token.text += peek();
            advance();
        }
    }

    std::string_view text_;
    const std::string& source_;
    std::size_t i_ = 0;
    Pos pos_;
    int depth_ = 0; // open parentheses and brackets: newlines inside them are white space
};

// ---------------------------------------------------------------------------------------------
// Syntax tree and parser

struct Node;
using NodePtr = std::unique_ptr<Node>;

struct Argument
{
    std::string keyword; // empty for a positional argument
    Pos keyword_pos;
    NodePtr value;
};

struct Node
{
    enum class Kind
    {
        Number,
        Vector,
        String,
        Name,
        Call,
    };
    Kind kind = Kind::Number;
    Pos pos;
    double number = 0.0;
    std::string text;                // a name, a function's name, a string's content
    std::vector<NodePtr> components; // Vector
    std::vector<Argument> arguments; // Call
    Pos close_pos;                   // the ')' of a call
};

struct Statement
{
    bool binding = false;
    std::string name; // bindings
    Pos pos;          // the statement's first token
    Pos name_pos;
    NodePtr expr;
};

class Parser
{
public:
    Parser(std::vector<Token> tokens, const std::string& source)
        : tokens_(std::move(tokens)), source_(source)
    {}

    std::vector<Statement> parse_scene()
    {
        std::vector<Statement> statements;
        skip_separators();
        while (peek().kind != Tok::End)
        {
            statements.push_back(parse_statement());
            const Token& next = peek();
            if (next.kind == Tok::Separator)
            {
                skip_separators();
                continue;
            }
            if (next.kind == Tok::End)
            {
                break;
            }
            const Statement& last = statements.back();
            const std::string after =
                last.binding ? "the binding of '" + last.name + "'" : "the expression";
            if (next.kind == Tok::RParen || next.kind == Tok::RBracket)
            {
                fail(next.pos, "unexpected " + describe(next) + " after " + after + ": no '" +
                                   (next.kind == Tok::RParen ? "(" : "[") + "' is open");
            }
            fail(next.pos,
                 "expected end of line or ';' after " + after + ", found " + describe(next));
        }
        return statements;
    }

    [[nodiscard]] Pos end_pos() const { return tokens_.back().pos; }

private:
    [[nodiscard]] const Token& peek(std::size_t ahead = 0) const
    {
        return tokens_[std::min(i_ + ahead, tokens_.size() - 1)];
    }
    const Token& next()
    {
        const Token& token = tokens_[i_];
        if (i_ + 1 < tokens_.size())
        {
            ++i_;
        }
        return token;
    }
    void skip_separators()
    {
        while (peek().kind == Tok::Separator)
        {
            next();
        }
    }

    [[noreturn]] void fail(Pos pos, const std::string& message) const
    {
        throw InvalidInput(source_ + ":" + to_string(pos) + ": " + message);
    }

    Statement parse_statement()
    {
        Statement statement;
        statement.pos = peek().pos;
        const bool has_let = peek().kind == Tok::Name && peek().text == "let";
        if (has_let || (peek().kind == Tok::Name && peek(1).kind == Tok::Equals))
        {
            if (has_let)
            {
                next();
                if (peek().kind != Tok::Name || peek().text == "let")
                {
                    fail(peek().pos, "expected a name after 'let', found " + describe(peek()));
                }
            }
            const Token& name = next();
            statement.binding = true;
            statement.name = name.text;
            statement.name_pos = name.pos;
            if (peek().kind != Tok::Equals)
            {
                fail(peek().pos,
                     "expected '=' after 'let " + name.text + "', found " + describe(peek()));
            }
            next();
            statement.expr = parse_expr("an expression after '" + name.text + " ='");
            return statement;
        }
        statement.expr = parse_expr("an expression");
        return statement;
    }

    NodePtr parse_expr(const std::string& expected)
    {
        const Token& token = peek();
        auto node = std::make_unique<Node>();
        node->pos = token.pos;
        switch (token.kind)
        {
            case Tok::Number:
                node->kind = Node::Kind::Number;
                node->number = token.number;
                node->text = token.text;
                next();
                return node;
            case Tok::String:
                node->kind = Node::Kind::String;
                node->text = token.text;
                next();
                return node;
            case Tok::LBracket:
                return parse_vector();
            case Tok::Name:
                if (token.text == "let")
                {
                    fail(token.pos,
                         "expected " + expected +
                             ", found 'let' ('let name = ...' binds a name and stands at "
                             "the start of a statement)");
                }
                if (peek(1).kind == Tok::LParen)
                {
                    return parse_call();
                }
                node->kind = Node::Kind::Name;
                node->text = token.text;
                next();
                return node;
            default:
                break;
        }
        fail(token.pos, "expected " + expected + ", found " + describe(token));
    }

    /// Counts one more open '(' or '[' while it lives; refuses more than max_nesting.
    class Nesting
    {
    public:
        Nesting(Parser& parser, Pos open) : parser_(parser)
        {
            if (++parser_.nesting_ > max_nesting)
            {
                parser_.fail(open, "nested too deep: more than " + std::to_string(max_nesting) +
                                       " calls and vectors open at once");
            }
        }
        ~Nesting() { --parser_.nesting_; }
        Nesting(const Nesting&) = delete;
        Nesting& operator=(const Nesting&) = delete;
        Nesting(Nesting&&) = delete;
        Nesting& operator=(Nesting&&) = delete;

    private:
        Parser& parser_;
    };

    NodePtr parse_call()
    {
        auto node = std::make_unique<Node>();
        const Token& name = next();
        node->kind = Node::Kind::Call;
        node->pos = name.pos;
        node->text = name.text;
        const Pos open = next().pos; // '('
        const Nesting nesting(*this, open);
        std::size_t count = 0;
        bool seen_keyword = false;
        while (peek().kind != Tok::RParen)
        {
            ++count;
            const std::string ordinal = std::to_string(count);
            Argument argument;
            if (peek().kind == Tok::Name && peek(1).kind == Tok::Equals)
            {
                argument.keyword = peek().text;
                argument.keyword_pos = peek().pos;
                next();
                next();
                argument.value = parse_expr("a value for '" + argument.keyword + "' (argument " +
                                            ordinal + " of " + node->text + ")");
                seen_keyword = true;
            }
            else
            {
                const Pos at = peek().pos;
                argument.value =
                    parse_expr("an expression for argument " + ordinal + " of " + node->text);
                if (seen_keyword)
                {
                    fail(at, "positional argument " + ordinal + " of " + node->text +
                                 " after a keyword argument: positional arguments come first");
                }
            }
            node->arguments.push_back(std::move(argument));
            if (peek().kind == Tok::Comma)
            {
                next();
                continue;
            }
            if (peek().kind != Tok::RParen)
            {
                std::string message = "expected ',' or ')' after argument " + ordinal + " of " +
                                      node->text + ", found " + describe(peek());
                if (peek().kind == Tok::End)
                {
                    message += " (the '(' at " + to_string(open) + " is not closed)";
                }
                fail(peek().pos, message);
            }
        }
        node->close_pos = next().pos; // ')'
        return node;
    }

    NodePtr parse_vector()
    {
        auto node = std::make_unique<Node>();
        node->kind = Node::Kind::Vector;
        node->pos = next().pos; // '['
        const Nesting nesting(*this, node->pos);
        while (peek().kind != Tok::RBracket)
        {
            const std::size_t count = node->components.size() + 1;
            if (count > 3)
            {
                fail(peek().pos, "a vector has 3 components [x, y, z]; found a 4th");
            }
            node->components.push_back(
                parse_expr("a number for component " + std::to_string(count) + " of the vector"));
            if (peek().kind == Tok::Comma)
            {
                next();
                continue;
            }
            if (peek().kind != Tok::RBracket)
            {
                std::string message = "expected ',' or ']' after component " +
                                      std::to_string(count) + " of the vector, found " +
                                      describe(peek());
                if (peek().kind == Tok::End)
                {
                    message += " (the '[' at " + to_string(node->pos) + " is not closed)";
                }
                fail(peek().pos, message);
            }
        }
        next(); // ']'
        if (node->components.size() != 3)
        {
            fail(node->pos, "a vector has 3 components [x, y, z], found " +
                                std::to_string(node->components.size()));
        }
        return node;
    }

    std::vector<Token> tokens_;
    const std::string& source_;
    std::size_t i_ = 0;
    int nesting_ = 0; // open calls and vectors
};

// ---------------------------------------------------------------------------------------------
// Values and the function table

enum class Type
{
    Number,
    Vector,
    String,
    Field,
};

struct Value
{
    Type type = Type::Number;
    double number = 0.0;
    Vec3d vector = Vec3d::Zero();
    std::string string;
    FieldPtr field; // null while checking
    int depth = 0;  // a field's nesting of operators and transforms (1: a primitive or a scan)
};

std::string describe(Type type)
{
    switch (type)
    {
        case Type::Number:
            return "a number";
        case Type::Vector:
            return "a vector [x, y, z]";
        case Type::String:
            return "a string";
        case Type::Field:
            return "a field (a shape)";
    }
    return "a value";
}

enum class ParamType
{
    Number,
    Vector,
    String,
    Field,
    NumberOrVector,
};

/// The range a parameter's value must lie in (checked before anything is built).
enum class Range
{
    Any,
    Positive,        // > 0 (every component of a vector)
    NonNegative,     // ≥ 0
    UnitInterval,    // [0, 1]
    AtLeastOne,      // ≥ 1
    NonZeroVector,   // ‖v‖ > 0
    BlendKindChoice, // a blend kind's name
};

struct Param
{
    std::string name;
    ParamType type = ParamType::Field;
    Range range = Range::Any;
    std::optional<Value> default_value; // unset: required
    std::string default_text;
};

/// The arguments of one call, after binding: one value per parameter, and a variadic
/// function's leading fields.
struct Arguments
{
    const std::vector<Param>* params = nullptr;
    std::vector<Value> values;
    std::vector<FieldPtr> members;
    int depth = 0; // the deepest field among the arguments

    [[nodiscard]] const Value& get(std::string_view name) const
    {
        for (std::size_t i = 0; i < params->size(); ++i)
        {
            if ((*params)[i].name == name)
            {
                return values[i];
            }
        }
        throw Error("scene: internal error: no parameter " + std::string(name));
    }
    [[nodiscard]] double number(std::string_view name) const { return get(name).number; }
    [[nodiscard]] const Vec3d& vector(std::string_view name) const { return get(name).vector; }
    [[nodiscard]] const FieldPtr& field(std::string_view name) const { return get(name).field; }
};

struct Function
{
    std::string name;
    /// 0: fixed parameters; otherwise the call starts with at least this many fields (the
    /// members), and `params` can only be given as keywords.
    std::size_t variadic_min = 0;
    std::vector<Param> params;
    std::function<FieldPtr(const Arguments&)> build; // unset for scan(), which the evaluator does
};

Value number_value(double x)
{
    return {.type = Type::Number, .number = x};
}
Value vector_value(double x, double y, double z)
{
    return {.type = Type::Vector, .vector = Vec3d(x, y, z)};
}
Value string_value(std::string s)
{
    return {.type = Type::String, .string = std::move(s)};
}

Param field_param(std::string name)
{
    return {.name = std::move(name), .type = ParamType::Field};
}
Param required(std::string name, ParamType type, Range range = Range::Any)
{
    return {.name = std::move(name), .type = type, .range = range};
}
Param optional(std::string name, ParamType type, Range range, Value value, std::string text)
{
    return {.name = std::move(name),
            .type = type,
            .range = range,
            .default_value = std::move(value),
            .default_text = std::move(text)};
}

std::optional<BlendKind> parse_blend_kind(std::string_view text)
{
    if (text == "linear")
    {
        return BlendKind::Linear;
    }
    if (text == "hyperbolic")
    {
        return BlendKind::Hyperbolic;
    }
    if (text == "super_elliptic" || text == "super-elliptic" || text == "superelliptic")
    {
        return BlendKind::SuperElliptic;
    }
    return std::nullopt;
}

Mat3d rotation_about(const Vec3d& axis, double degrees)
{
    return Eigen::AngleAxisd(degrees * std::numbers::pi / 180.0, axis.normalized())
        .toRotationMatrix();
}

std::vector<Function> make_function_table()
{
    const Value origin = vector_value(0, 0, 0);
    std::vector<Function> table;
    table.push_back({.name = "scan", .params = {required("path", ParamType::String)}});
    table.push_back({.name = "sphere",
                     .params = {required("center", ParamType::Vector),
                                required("radius", ParamType::Number, Range::Positive)},
                     .build = [](const Arguments& a) {
                         return make_sphere(a.vector("center"), a.number("radius"));
                     }});
    table.push_back(
        {.name = "box",
         .params = {required("min", ParamType::Vector), required("max", ParamType::Vector),
                    optional("rounded", ParamType::Number, Range::NonNegative, number_value(0),
                             "0")},
         .build = [](const Arguments& a) {
             return make_box(a.vector("min"), a.vector("max"), a.number("rounded"));
         }});
    table.push_back(
        {.name = "oriented_box",
         .params = {required("center", ParamType::Vector),
                    required("half_extents", ParamType::Vector, Range::Positive),
                    optional("axis", ParamType::Vector, Range::NonZeroVector, vector_value(0, 0, 1),
                             "[0, 0, 1]"),
                    optional("degrees", ParamType::Number, Range::Any, number_value(0), "0"),
                    optional("rounded", ParamType::Number, Range::NonNegative, number_value(0),
                             "0")},
         .build = [](const Arguments& a) {
             return make_oriented_box(a.vector("center"), a.vector("half_extents"),
                                      rotation_about(a.vector("axis"), a.number("degrees")),
                                      a.number("rounded"));
         }});
    table.push_back({.name = "cylinder",
                     .params = {required("a", ParamType::Vector), required("b", ParamType::Vector),
                                required("radius", ParamType::Number, Range::Positive)},
                     .build = [](const Arguments& a) {
                         return make_cylinder(a.vector("a"), a.vector("b"), a.number("radius"));
                     }});
    table.push_back({.name = "cone",
                     .params = {required("a", ParamType::Vector), required("b", ParamType::Vector),
                                required("radius_a", ParamType::Number, Range::NonNegative),
                                optional("radius_b", ParamType::Number, Range::NonNegative,
                                         number_value(0), "0")},
                     .build = [](const Arguments& a) {
                         return make_cone(a.vector("a"), a.vector("b"), a.number("radius_a"),
                                          a.number("radius_b"));
                     }});
    table.push_back({.name = "torus",
                     .params = {required("center", ParamType::Vector),
                                required("axis", ParamType::Vector, Range::NonZeroVector),
                                required("major_radius", ParamType::Number, Range::NonNegative),
                                required("minor_radius", ParamType::Number, Range::Positive)},
                     .build = [](const Arguments& a) {
                         return make_torus(a.vector("center"), a.vector("axis"),
                                           a.number("major_radius"), a.number("minor_radius"));
                     }});
    table.push_back({.name = "half_space",
                     .params = {required("point", ParamType::Vector),
                                required("normal", ParamType::Vector, Range::NonZeroVector)},
                     .build = [](const Arguments& a) {
                         return make_half_space(a.vector("point"), a.vector("normal"));
                     }});
    table.push_back({.name = "union", .variadic_min = 2, .build = [](const Arguments& a) {
                         return make_union(a.members);
                     }});
    table.push_back({.name = "intersection", .variadic_min = 2, .build = [](const Arguments& a) {
                         return make_intersection(a.members);
                     }});
    table.push_back(
        {.name = "difference", .variadic_min = 2, .build = [](const Arguments& a) -> FieldPtr {
             if (a.members.size() == 2)
             {
                 return make_difference(a.members[0], a.members[1]);
             }
             return std::make_shared<const BooleanField>(BooleanOp::Difference, a.members);
         }});
    const auto smooth = [](std::string name, auto factory) {
        return Function{.name = std::move(name),
                        .params = {field_param("a"), field_param("b"),
                                   required("radius", ParamType::Number, Range::Positive)},
                        .build = [factory](const Arguments& a) {
                            return factory(a.field("a"), a.field("b"), a.number("radius"));
                        }};
    };
    table.push_back(smooth("smooth_union", &make_smooth_union));
    table.push_back(smooth("smooth_intersection", &make_smooth_intersection));
    table.push_back(smooth("smooth_difference", &make_smooth_difference));
    table.push_back(
        {.name = "blend",
         .variadic_min = 1,
         .params = {required("range", ParamType::Number, Range::Positive),
                    optional("kind", ParamType::String, Range::BlendKindChoice,
                             string_value("linear"), "\"linear\""),
                    optional("beta", ParamType::Number, Range::AtLeastOne, number_value(2), "2")},
         .build = [](const Arguments& a) {
             return make_blend(*parse_blend_kind(a.get("kind").string), a.members,
                               a.number("range"), a.number("beta"));
         }});
    table.push_back({.name = "offset",
                     .params = {field_param("a"), required("distance", ParamType::Number)},
                     .build = [](const Arguments& a) {
                         return make_offset(a.field("a"), a.number("distance"));
                     }});
    table.push_back(
        {.name = "shell",
         .params = {field_param("a"), required("thickness", ParamType::Number, Range::Positive)},
         .build = [](const Arguments& a) {
             return make_shell(a.field("a"), a.number("thickness"));
         }});
    table.push_back({.name = "morph",
                     .params = {field_param("a"), field_param("b"),
                                required("t", ParamType::Number, Range::UnitInterval)},
                     .build = [](const Arguments& a) {
                         return make_morph(a.field("a"), a.field("b"), a.number("t"));
                     }});
    table.push_back({.name = "translate",
                     .params = {field_param("a"), required("offset", ParamType::Vector)},
                     .build = [](const Arguments& a) {
                         return translate(a.field("a"), a.vector("offset"));
                     }});
    table.push_back(
        {.name = "rotate",
         .params = {field_param("a"), required("axis", ParamType::Vector, Range::NonZeroVector),
                    required("degrees", ParamType::Number),
                    optional("center", ParamType::Vector, Range::Any, origin, "[0, 0, 0]")},
         .build = [](const Arguments& a) {
             return rotate(a.field("a"), a.vector("axis"),
                           a.number("degrees") * std::numbers::pi / 180.0, a.vector("center"));
         }});
    table.push_back(
        {.name = "scale",
         .params = {field_param("a"),
                    required("factor", ParamType::NumberOrVector, Range::Positive),
                    optional("center", ParamType::Vector, Range::Any, origin, "[0, 0, 0]")},
         .build = [](const Arguments& a) {
             const Value& factor = a.get("factor");
             if (factor.type == Type::Number)
             {
                 return scale(a.field("a"), factor.number, a.vector("center"));
             }
             return scale(a.field("a"), factor.vector, a.vector("center"));
         }});
    return table;
}

const std::vector<Function>& function_table()
{
    static const std::vector<Function> table = make_function_table();
    return table;
}

const Function* find_function(std::string_view name)
{
    for (const Function& function : function_table())
    {
        if (function.name == name)
        {
            return &function;
        }
    }
    return nullptr;
}

std::vector<std::string> function_names()
{
    std::vector<std::string> names;
    for (const Function& function : function_table())
    {
        names.push_back(function.name);
    }
    return names;
}

std::string signature(const Function& function)
{
    std::string text = function.name + "(";
    if (function.variadic_min > 0)
    {
        text += function.variadic_min == 1 ? "a, ..." : "a, b, ...";
    }
    for (std::size_t i = 0; i < function.params.size(); ++i)
    {
        const Param& param = function.params[i];
        if (i > 0 || function.variadic_min > 0)
        {
            text += ", ";
        }
        text += param.name;
        if (param.default_value)
        {
            text += " = " + param.default_text;
        }
    }
    return text + ")";
}

/// Names people try that are spelled otherwise here.
std::optional<std::string> known_alias(std::string_view name)
{
    static const std::map<std::string, std::string, std::less<>> aliases = {
        {"plane", "half_space"},    {"halfspace", "half_space"},
        {"ball", "sphere"},         {"cube", "box"},
        {"subtract", "difference"}, {"minus", "difference"},
        {"cut", "difference"},      {"intersect", "intersection"},
        {"paste", "union"},         {"move", "translate"},
        {"thicken", "shell"},       {"dilate", "offset"},
        {"capsule", "cylinder"},    {"load", "scan"},
        {"points", "scan"},
    };
    const auto it = aliases.find(name);
    if (it == aliases.end())
    {
        return std::nullopt;
    }
    return it->second;
}

// ---------------------------------------------------------------------------------------------
// Checking and building

class Evaluator
{
public:
    Evaluator(const SceneOptions& options, std::vector<Statement> statements, Pos end)
        : options_(options), statements_(std::move(statements)), end_(end)
    {}

    Scene run()
    {
        const Node& result = check();
        // The bindings the result needs, through the bindings they use (each refers only to
        // earlier ones), and how many times each is named there.
        const std::size_t n = statements_.size();
        std::vector<bool> needed(n, false);
        std::vector<std::size_t> uses(n, 0);
        needed[n - 1] = true;
        for (std::size_t i = n; i-- > 0;)
        {
            if (!needed[i])
            {
                continue;
            }
            for (const std::size_t used : references_[i])
            {
                needed[used] = true;
                ++uses[used];
            }
        }
        // Built in order, each once: a field named more than once becomes one shared node,
        // evaluated once per batch of points whatever the number of paths to it.
        building_ = true;
        for (std::size_t i = 0; i + 1 < n; ++i)
        {
            if (!needed[i])
            {
                continue;
            }
            Binding& binding = bindings_.at(statements_[i].name);
            Value value = evaluate(*statements_[i].expr);
            if (value.type == Type::Field && uses[i] > 1)
            {
                value.field = make_shared_node(std::move(value.field));
            }
            binding.built = std::move(value);
        }
        Scene scene;
        scene.field = evaluate(result).field;
        scene.scans = std::move(scans_);
        return scene;
    }

private:
    struct Binding
    {
        Pos pos;
        std::size_t statement = 0;
        Value checked;
        std::optional<Value> built;
    };

    [[noreturn]] void fail(Pos pos, const std::string& message) const
    {
        throw InvalidInput(options_.source_name + ":" + to_string(pos) + ": " + message);
    }

    /// Checks every statement in order, before anything is built; returns the result's node.
    const Node& check()
    {
        if (statements_.empty())
        {
            fail(end_, "empty scene: expected an expression, found end of input");
        }
        for (std::size_t i = 0; i < statements_.size(); ++i)
        {
            const Statement& statement = statements_[i];
            const bool last = i + 1 == statements_.size();
            if (!statement.binding && !last)
            {
                fail(statement.pos,
                     "only the last statement is the scene's result; bind this expression to a "
                     "name ('let name = ...') or remove it");
            }
            if (statement.binding && statement.name == "result" && !last)
            {
                fail(statement.name_pos,
                     "'result' names the scene's result and must be the last statement");
            }
            if (statement.binding)
            {
                if (find_function(statement.name) != nullptr)
                {
                    fail(statement.name_pos, "'" + statement.name +
                                                 "' is a function's name; choose another name "
                                                 "for the binding");
                }
                const auto previous = bindings_.find(statement.name);
                if (previous != bindings_.end())
                {
                    fail(statement.name_pos, "'" + statement.name + "' is already bound at " +
                                                 to_string(previous->second.pos) +
                                                 "; choose another name");
                }
            }
            references_.emplace_back();
            Value value = evaluate(*statement.expr);
            if (statement.binding && statement.name != "result")
            {
                bindings_[statement.name] = {
                    .pos = statement.name_pos, .statement = i, .checked = value};
            }
            if (last)
            {
                if (statement.binding && statement.name != "result")
                {
                    fail(end_,
                         "expected the scene's result (an expression, or 'result = ...') "
                         "after the binding of '" +
                             statement.name + "', found end of input");
                }
                if (value.type != Type::Field)
                {
                    fail(statement.expr->pos,
                         "the scene's result must be a field (a shape), "
                         "found " +
                             describe(value.type));
                }
            }
        }
        return *statements_.back().expr;
    }

    Value evaluate(const Node& node)
    {
        switch (node.kind)
        {
            case Node::Kind::Number:
                return number_value(node.number);
            case Node::Kind::String:
                return string_value(node.text);
            case Node::Kind::Vector:
            {
                Value value{.type = Type::Vector};
                for (std::size_t c = 0; c < 3; ++c)
                {
                    const Node& component = *node.components[c];
                    const Value v = evaluate(component);
                    if (v.type != Type::Number)
                    {
                        fail(component.pos, "component " + std::to_string(c + 1) +
                                                " of a vector must be a number, found " +
                                                describe(v.type));
                    }
                    value.vector[static_cast<Eigen::Index>(c)] = v.number;
                }
                return value;
            }
            case Node::Kind::Name:
                return lookup(node);
            case Node::Kind::Call:
                return call(node);
        }
        fail(node.pos, "internal error: unknown node");
    }

    Value lookup(const Node& node)
    {
        const auto it = bindings_.find(node.text);
        if (it == bindings_.end())
        {
            if (const Function* function = find_function(node.text))
            {
                fail(node.pos,
                     "'" + node.text + "' is a function; call it as " + signature(*function));
            }
            std::vector<std::string> names;
            for (const auto& [name, binding] : bindings_)
            {
                names.push_back(name);
            }
            const std::string suggestion = did_you_mean(node.text, names);
            fail(node.pos,
                 "undefined name '" + node.text + "'" +
                     (suggestion.empty() ? " (bind it first: 'let " + node.text + " = ...')"
                                         : suggestion));
        }
        Binding& binding = it->second;
        if (!building_)
        {
            references_.back().push_back(binding.statement);
            return binding.checked;
        }
        if (!binding.built)
        {
            fail(node.pos, "internal error: '" + node.text + "' is not built");
        }
        return *binding.built;
    }

    Value call(const Node& node)
    {
        const Function* function = find_function(node.text);
        if (function == nullptr)
        {
            std::string suggestion = did_you_mean(node.text, function_names());
            if (suggestion.empty())
            {
                if (const auto alias = known_alias(node.text))
                {
                    suggestion = "; did you mean '" + *alias + "'?";
                }
            }
            if (suggestion.empty())
            {
                std::string known;
                for (const std::string& name : function_names())
                {
                    known += (known.empty() ? "" : ", ") + name;
                }
                suggestion = " (known functions: " + known + ")";
            }
            fail(node.pos, "unknown function '" + node.text + "'" + suggestion);
        }
        const Arguments arguments = bind_arguments(*function, node);
        if (function->name == "scan")
        {
            return {
                .type = Type::Field, .field = scan(node, arguments.get("path").string), .depth = 1};
        }
        Value value{.type = Type::Field, .depth = arguments.depth + 1};
        if (value.depth > max_nesting)
        {
            fail(node.pos, function->name + " nests the scene's field too deep: more than " +
                               std::to_string(max_nesting) +
                               " operators and transforms inside one another (through bindings)");
        }
        if (building_)
        {
            try
            {
                value.field = function->build(arguments);
            }
            catch (const InvalidInput& e)
            {
                const std::string message = e.what();
                const bool named = message.rfind(function->name + ":", 0) == 0;
                fail(node.pos, (named ? "" : function->name + ": ") + message);
            }
        }
        return value;
    }

    Arguments bind_arguments(const Function& function, const Node& node)
    {
        Arguments arguments{.params = &function.params};
        arguments.values.resize(function.params.size());
        std::vector<bool> given(function.params.size(), false);
        std::size_t positional = 0;
        for (std::size_t i = 0; i < node.arguments.size(); ++i)
        {
            const Argument& argument = node.arguments[i];
            const std::string ordinal = std::to_string(i + 1);
            Value value = evaluate(*argument.value);
            if (value.type == Type::Field)
            {
                arguments.depth = std::max(arguments.depth, value.depth);
            }
            if (argument.keyword.empty())
            {
                ++positional;
                if (function.variadic_min > 0)
                {
                    if (value.type != Type::Field)
                    {
                        std::string hint;
                        if (!function.params.empty())
                        {
                            hint = "; its other parameters are given by keyword, e.g. " +
                                   function.params[0].name + " = ...";
                        }
                        fail(argument.value->pos, "argument " + ordinal + " of " + function.name +
                                                      " must be a field, found " +
                                                      describe(value.type) + " (" +
                                                      signature(function) + hint + ")");
                    }
                    arguments.members.push_back(value.field);
                    continue;
                }
                if (positional > function.params.size())
                {
                    fail(argument.value->pos,
                         "too many arguments to " + function.name + ": it takes " +
                             std::to_string(function.params.size()) + ", " + signature(function));
                }
                const std::size_t p = positional - 1;
                check_value(function, function.params[p], value, *argument.value);
                arguments.values[p] = std::move(value);
                given[p] = true;
                continue;
            }
            std::size_t p = 0;
            while (p < function.params.size() && function.params[p].name != argument.keyword)
            {
                ++p;
            }
            if (p == function.params.size())
            {
                std::vector<std::string> names;
                for (const Param& param : function.params)
                {
                    names.push_back(param.name);
                }
                fail(argument.keyword_pos,
                     function.name + " has no parameter '" + argument.keyword + "'" +
                         did_you_mean(argument.keyword, names) + " (" + signature(function) + ")");
            }
            if (given[p])
            {
                fail(argument.keyword_pos,
                     "argument '" + argument.keyword + "' of " + function.name + " is given twice");
            }
            check_value(function, function.params[p], value, *argument.value);
            arguments.values[p] = std::move(value);
            given[p] = true;
        }
        if (function.variadic_min > 0 && arguments.members.size() < function.variadic_min)
        {
            fail(node.close_pos,
                 function.name + " needs at least " + std::to_string(function.variadic_min) +
                     " field" + (function.variadic_min == 1 ? "" : "s") + ", found " +
                     std::to_string(arguments.members.size()) + " (" + signature(function) + ")");
        }
        for (std::size_t p = 0; p < function.params.size(); ++p)
        {
            if (given[p])
            {
                continue;
            }
            const Param& param = function.params[p];
            if (!param.default_value)
            {
                fail(node.close_pos,
                     "missing argument '" + param.name + "' of " + signature(function));
            }
            arguments.values[p] = *param.default_value;
        }
        return arguments;
    }

    void check_value(const Function& function, const Param& param, const Value& value,
                     const Node& at) const
    {
        const std::string what = "argument '" + param.name + "' of " + function.name;
        bool type_ok = false;
        std::string expected;
        switch (param.type)
        {
            case ParamType::Number:
                type_ok = value.type == Type::Number;
                expected = describe(Type::Number);
                break;
            case ParamType::Vector:
                type_ok = value.type == Type::Vector;
                expected = describe(Type::Vector);
                break;
            case ParamType::String:
                type_ok = value.type == Type::String;
                expected = "a string \"...\"";
                break;
            case ParamType::Field:
                type_ok = value.type == Type::Field;
                expected = describe(Type::Field);
                break;
            case ParamType::NumberOrVector:
                type_ok = value.type == Type::Number || value.type == Type::Vector;
                expected = "a number or a vector [x, y, z]";
                break;
        }
        if (!type_ok)
        {
            fail(at.pos, what + " must be " + expected + ", found " + describe(value.type));
        }
        const auto got = [&value] {
            std::ostringstream text;
            if (value.type == Type::Number)
            {
                text << value.number;
            }
            else
            {
                text << '[' << value.vector.x() << ", " << value.vector.y() << ", "
                     << value.vector.z() << ']';
            }
            return text.str();
        };
        const auto all = [&value](auto predicate) {
            if (value.type == Type::Number)
            {
                return predicate(value.number);
            }
            return predicate(value.vector.x()) && predicate(value.vector.y()) &&
                   predicate(value.vector.z());
        };
        switch (param.range)
        {
            case Range::Any:
                break;
            case Range::Positive:
                if (!all([](double x) { return x > 0.0; }))
                {
                    fail(at.pos, what + " must be > 0" +
                                     (value.type == Type::Vector ? " in every component" : "") +
                                     ", found " + got());
                }
                break;
            case Range::NonNegative:
                if (!all([](double x) { return x >= 0.0; }))
                {
                    fail(at.pos, what + " must be ≥ 0, found " + got());
                }
                break;
            case Range::UnitInterval:
                if (!all([](double x) { return x >= 0.0 && x <= 1.0; }))
                {
                    fail(at.pos, what + " must be in [0, 1], found " + got());
                }
                break;
            case Range::AtLeastOne:
                if (!all([](double x) { return x >= 1.0; }))
                {
                    fail(at.pos, what + " must be ≥ 1, found " + got());
                }
                break;
            case Range::NonZeroVector:
                if (!(value.vector.norm() > 0.0))
                {
                    fail(at.pos, what + " must be a non-zero vector, found " + got());
                }
                break;
            case Range::BlendKindChoice:
                if (!parse_blend_kind(value.string))
                {
                    fail(
                        at.pos,
                        what +
                            " must be \"linear\", \"hyperbolic\" or \"super_elliptic\", found \"" +
                            value.string + "\"" +
                            did_you_mean(value.string, {"linear", "hyperbolic", "super_elliptic"}));
                }
                break;
        }
    }

    std::filesystem::path resolve(const std::string& path) const
    {
        std::filesystem::path resolved(path);
        if (resolved.is_relative() && !options_.base_directory.empty())
        {
            resolved = options_.base_directory / resolved;
        }
        return resolved.lexically_normal();
    }

    FieldPtr scan(const Node& node, const std::string& path)
    {
        if (path.empty())
        {
            fail(node.arguments.front().value->pos, "scan needs a file name, found \"\"");
        }
        if (!options_.load_scan)
        {
            fail(node.pos, "scan(\"" + path + "\") is not available here (no scan loader)");
        }
        const std::filesystem::path resolved = resolve(path);
        std::error_code error;
        if (!std::filesystem::is_regular_file(resolved, error))
        {
            const bool exists = std::filesystem::exists(resolved, error);
            fail(node.arguments.front().value->pos,
                 std::string(exists ? "scan file is not a regular file: '"
                                    : "scan file not found: '") +
                     resolved.string() + "'" +
                     (resolved.string() == path
                          ? ""
                          : " (\"" + path + "\" resolved against " +
                                (options_.base_directory.empty()
                                     ? std::string("the current directory")
                                     : "'" + options_.base_directory.string() + "'") +
                                ")"));
        }
        if (!building_)
        {
            return nullptr;
        }
        std::filesystem::path key = std::filesystem::weakly_canonical(resolved, error);
        if (error)
        {
            key = resolved;
        }
        const auto it = loaded_.find(key.string());
        if (it != loaded_.end())
        {
            return it->second;
        }
        FieldPtr field;
        try
        {
            field = options_.load_scan(resolved.string());
        }
        catch (const InvalidInput& e)
        {
            fail(node.pos, "scan(\"" + path + "\"): " + e.what());
        }
        if (!field)
        {
            fail(node.pos, "scan(\"" + path + "\"): the scan loader returned no field");
        }
        loaded_.emplace(key.string(), field);
        scans_.push_back(resolved.string());
        return field;
    }

    const SceneOptions& options_;
    std::vector<Statement> statements_;
    Pos end_;
    bool building_ = false;
    std::map<std::string, Binding, std::less<>> bindings_;
    /// Per statement checked so far: the statements of the bindings it names, once per mention.
    std::vector<std::vector<std::size_t>> references_;
    std::map<std::string, FieldPtr, std::less<>> loaded_;
    std::vector<std::string> scans_;
};

} // namespace

Scene parse_scene(std::string_view text, const SceneOptions& options)
{
    Lexer lexer(text, options.source_name);
    Parser parser(lexer.tokenize(), options.source_name);
    std::vector<Statement> statements = parser.parse_scene();
    Evaluator evaluator(options, std::move(statements), parser.end_pos());
    return evaluator.run();
}

Scene read_scene(const std::filesystem::path& path, ScanLoader load_scan)
{
    std::ifstream file(path, std::ios::binary);
    if (!file)
    {
        throw IoError(path, "cannot open the scene file");
    }
    std::ostringstream text;
    text << file.rdbuf();
    if (file.bad())
    {
        throw IoError(path, "cannot read the scene file");
    }
    SceneOptions options;
    options.source_name = path.string();
    options.base_directory = path.parent_path();
    options.load_scan = std::move(load_scan);
    return parse_scene(text.str(), options);
}

bool looks_like_file(std::string_view argument)
{
    if (argument.empty() || argument.find('\n') != std::string_view::npos)
    {
        return false;
    }
    std::error_code error;
    return std::filesystem::exists(std::filesystem::path(argument), error);
}

std::string scene_function_summary()
{
    std::string text;
    for (const Function& function : function_table())
    {
        text += signature(function) + "\n";
    }
    return text;
}

} // namespace pointform
