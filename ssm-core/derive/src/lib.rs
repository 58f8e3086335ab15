//! Derives for ssm-core: [`Settings`](macro@Settings) and [`Choice`](macro@Choice).
//!
//! A technique declares its settings once, as a documented struct; the derive
//! makes the string parameters (`ssm list`, `--set`, sweeps) from it, so that
//! no parameter's name, default, range or documentation is written twice.
//!
//! # Example
//!
//! ```
//! # fn main() -> Result<(), ssm_core::ParamError> {
//! use ssm_core::{Choice, ParamValues, Settings};
//!
//! /// How the taps are spread.
//! #[derive(Clone, Copy, Debug, PartialEq, Eq, Choice)]
//! enum Pattern {
//!     /// A regular grid.
//!     Grid,
//!     /// A Poisson disc.
//!     Poisson,
//! }
//!
//! /// A filter's settings: each field a parameter, its doc comment the parameter's meaning.
//! #[derive(Clone, Copy, Debug, PartialEq, Settings)]
//! struct FilterSettings {
//!     /// Taps per axis, count.
//!     #[param(default = 3, min = 1, max = 16)]
//!     kernel: u32,
//!     /// Half the filter's side, shadow-map texels.
//!     #[param(default = 1.5, min = 0.0, max = 32.0)]
//!     radius: f32,
//!     /// Where the taps go.
//!     #[param(choice, default = "grid")]
//!     pattern: Pattern,
//! }
//!
//! let names: Vec<&str> = FilterSettings::PARAMS.iter().map(|spec| spec.name).collect();
//! assert_eq!(names, ["kernel", "radius", "pattern"]);
//! // What `--set mine.kernel=5 --set mine.pattern=poisson` does.
//! let mut values = ParamValues::defaults("mine", FilterSettings::PARAMS);
//! values.set("kernel", "5")?;
//! values.set("pattern", "poisson")?;
//! let settings = FilterSettings::from_params(&values)?;
//! assert_eq!(settings, FilterSettings { kernel: 5, radius: 1.5, pattern: Pattern::Poisson });
//! // Out of range is a typed error, not a clamp.
//! assert!(values.set("kernel", "17").is_err());
//! # Ok(())
//! # }
//! ```

use proc_macro::TokenStream;
use proc_macro2::TokenStream as Tokens;
use quote::{format_ident, quote};
use syn::spanned::Spanned;
use syn::{Data, DeriveInput, Expr, Fields, Ident, Lit, LitStr, Type};

/// Derives `ssm_core::Settings` for a struct with named fields.
///
/// Each field is a parameter named after it, documented by its doc comment
/// (say the unit there), with `#[param(...)]`:
///
/// - `default = <value>`: the default (a string naming the option for a choice);
/// - `min = <value>, max = <value>`: the valid range of a number (both required);
///   values are literals or constant expressions (a shared constant, say);
/// - `choice`: the field's type is an enum deriving `Choice`;
/// - `flatten`: the field's type derives `Settings` itself, and its parameters are
///   this struct's too (settings several techniques share);
/// - `name = "..."`: a parameter name other than the field's.
///
/// `bool` fields are flags; `u32`, `u64`, `usize`, `i32` and `i64` are
/// integers; `f32` and `f64` are numbers. The derive also implements `Default`
/// with the declared defaults.
#[proc_macro_derive(Settings, attributes(param))]
pub fn derive_settings(input: TokenStream) -> TokenStream {
    let input = syn::parse_macro_input!(input as DeriveInput);
    settings(&input).unwrap_or_else(syn::Error::into_compile_error).into()
}

/// Derives `ssm_core::Choice` for an enum of unit variants: a parameter taking
/// one of a fixed set of words, each variant's name in snake case unless
/// `#[choice(name = "...")]` says otherwise.
#[proc_macro_derive(Choice, attributes(choice))]
pub fn derive_choice(input: TokenStream) -> TokenStream {
    let input = syn::parse_macro_input!(input as DeriveInput);
    choice(&input).unwrap_or_else(syn::Error::into_compile_error).into()
}

/// What a field's `#[param(...)]` says.
#[derive(Default)]
struct ParamAttributes {
    default: Option<Expr>,
    min: Option<Expr>,
    max: Option<Expr>,
    choice: bool,
    flatten: bool,
    name: Option<LitStr>,
}

fn param_attributes(field: &syn::Field) -> syn::Result<ParamAttributes> {
    let mut out = ParamAttributes::default();
    for attribute in field.attrs.iter().filter(|a| a.path().is_ident("param")) {
        attribute.parse_nested_meta(|meta| {
            let literal = |meta: &syn::meta::ParseNestedMeta<'_>| -> syn::Result<Expr> { meta.value()?.parse() };
            if meta.path.is_ident("default") {
                out.default = Some(literal(&meta)?);
            } else if meta.path.is_ident("min") {
                out.min = Some(literal(&meta)?);
            } else if meta.path.is_ident("max") {
                out.max = Some(literal(&meta)?);
            } else if meta.path.is_ident("choice") {
                out.choice = true;
            } else if meta.path.is_ident("flatten") {
                out.flatten = true;
            } else if meta.path.is_ident("name") {
                out.name = Some(meta.value()?.parse()?);
            } else {
                return Err(meta.error("expected default, min, max, choice, flatten or name"));
            }
            Ok(())
        })?;
    }
    Ok(out)
}

/// The doc comment of `attrs`, lines joined by spaces (blank lines dropped).
fn doc_of(attrs: &[syn::Attribute]) -> String {
    let lines: Vec<String> = doc_lines(attrs).into_iter().map(|line| line.trim().to_owned()).filter(|line| !line.is_empty()).collect();
    lines.join(" ")
}

/// The last path segment of a type (`u32`, `f32`, `Filter`).
fn type_name(ty: &Type) -> Option<String> {
    match ty {
        Type::Path(path) => path.path.segments.last().map(|s| s.ident.to_string()),
        _ => None,
    }
}

/// A number's value as the `i64` or `f64` a `ParamKind` holds: literals checked here, other
/// constant expressions converted with `as`.
fn number_value(expr: &Expr, float: bool) -> syn::Result<Tokens> {
    match expr {
        Expr::Lit(syn::ExprLit { lit: Lit::Int(int), .. }) if !float => {
            let value: i64 = int.base10_parse()?;
            Ok(quote!(#value))
        }
        Expr::Lit(syn::ExprLit { lit: Lit::Int(int), .. }) => {
            let value: f64 = int.base10_parse()?;
            Ok(quote!(#value))
        }
        Expr::Lit(syn::ExprLit { lit: Lit::Float(number), .. }) if float => {
            let value: f64 = number.base10_parse()?;
            Ok(quote!(#value))
        }
        Expr::Lit(other) => Err(syn::Error::new(other.span(), if float { "expected a number" } else { "expected an integer" })),
        other if float => Ok(quote!(((#other) as f64))),
        other => Ok(quote!(((#other) as i64))),
    }
}

fn settings(input: &DeriveInput) -> syn::Result<Tokens> {
    let name = &input.ident;
    let Data::Struct(data) = &input.data else {
        return Err(syn::Error::new(input.span(), "Settings derives only for structs with named fields"));
    };
    let Fields::Named(fields) = &data.fields else {
        return Err(syn::Error::new(input.span(), "Settings derives only for structs with named fields"));
    };
    let core = quote!(::ssm_core);
    // Each part of PARAMS: one ParamSpec of this struct, or a flattened struct's slice.
    let mut parts: Vec<Tokens> = Vec::new();
    let mut lengths: Vec<Tokens> = Vec::new();
    let mut reads: Vec<Tokens> = Vec::new();
    let mut defaults: Vec<Tokens> = Vec::new();
    for field in &fields.named {
        let Some(ident) = &field.ident else { continue };
        let ty = &field.ty;
        let attributes = param_attributes(field)?;
        if attributes.flatten {
            parts.push(quote!(<#ty as #core::Settings>::PARAMS));
            lengths.push(quote!(<#ty as #core::Settings>::PARAMS.len()));
            reads.push(quote!(#ident: <#ty as #core::Settings>::from_params(values)?));
            defaults.push(quote!(#ident: <#ty as ::core::default::Default>::default()));
            continue;
        }
        let param_name = attributes.name.as_ref().map_or_else(|| ident.to_string(), LitStr::value);
        let doc = doc_of(&field.attrs);
        if doc.is_empty() {
            return Err(syn::Error::new(ident.span(), "document every parameter (its meaning and unit) with a doc comment"));
        }
        let Some(default) = &attributes.default else {
            return Err(syn::Error::new(ident.span(), "missing #[param(default = ...)]"));
        };
        let kind_name = type_name(ty).unwrap_or_default();
        let wrong = quote!(#core::ParamError::WrongType {
            technique: values.technique().into(),
            name: #param_name.into(),
            wanted: stringify!(#ty),
        });
        let (kind, read, default_value) = if attributes.choice {
            let Expr::Lit(syn::ExprLit { lit: Lit::Str(default_name), .. }) = default else {
                return Err(syn::Error::new(default.span(), "a choice's default is the option's name, as a string"));
            };
            (
                quote!(#core::ParamKind::Choice { default: #default_name, options: <#ty as #core::Choice>::OPTIONS }),
                quote!(<#ty as #core::Choice>::from_name(values.choice(#param_name)?).ok_or_else(|| #wrong)?),
                quote!(<#ty as #core::Choice>::from_name(#default_name).unwrap_or(<#ty as #core::Choice>::FIRST)),
            )
        } else {
            match kind_name.as_str() {
                "bool" => {
                    let Expr::Lit(syn::ExprLit { lit: Lit::Bool(flag), .. }) = default else {
                        return Err(syn::Error::new(default.span(), "a bool's default is true or false"));
                    };
                    (quote!(#core::ParamKind::Bool { default: #flag }), quote!(values.bool(#param_name)?), quote!(#flag))
                }
                "u32" | "u64" | "usize" | "i32" | "i64" => {
                    let (Some(min), Some(max)) = (&attributes.min, &attributes.max) else {
                        return Err(syn::Error::new(ident.span(), "an integer parameter needs #[param(min = ..., max = ...)]"));
                    };
                    let (default, min, max) = (number_value(default, false)?, number_value(min, false)?, number_value(max, false)?);
                    (
                        quote!(#core::ParamKind::Int { default: #default, min: #min, max: #max }),
                        quote!(<#ty>::try_from(values.int(#param_name)?).map_err(|_| #wrong)?),
                        quote!(#default as #ty),
                    )
                }
                "f32" | "f64" => {
                    let (Some(min), Some(max)) = (&attributes.min, &attributes.max) else {
                        return Err(syn::Error::new(ident.span(), "a number parameter needs #[param(min = ..., max = ...)]"));
                    };
                    let (default, min, max) = (number_value(default, true)?, number_value(min, true)?, number_value(max, true)?);
                    (
                        quote!(#core::ParamKind::Float { default: #default, min: #min, max: #max }),
                        quote!(values.float(#param_name)? as #ty),
                        quote!(#default as #ty),
                    )
                }
                _ => {
                    return Err(syn::Error::new(
                        ty.span(),
                        "parameters are bool, u32, u64, usize, i32, i64, f32 or f64; mark enums deriving Choice with #[param(choice)] and nested settings with #[param(flatten)]",
                    ));
                }
            }
        };
        parts.push(quote!(&[#core::ParamSpec { name: #param_name, kind: #kind, doc: #doc }]));
        lengths.push(quote!(1usize));
        reads.push(quote!(#ident: #read));
        defaults.push(quote!(#ident: #default_value));
    }
    let array = format_ident!("{}_PARAMS", name.to_string().to_uppercase());
    Ok(quote! {
        impl #core::Settings for #name {
            const PARAMS: &'static [#core::ParamSpec] = {
                const #array: [#core::ParamSpec; 0 #(+ #lengths)*] = #core::concat_params(&[#(#parts),*]);
                &#array
            };

            fn from_params(values: &#core::ParamValues) -> ::core::result::Result<Self, #core::ParamError> {
                ::core::result::Result::Ok(Self { #(#reads),* })
            }
        }

        impl ::core::default::Default for #name {
            fn default() -> Self {
                Self { #(#defaults),* }
            }
        }
    })
}

/// `CamelCase` to `snake_case`, digits kept with the letters before them (`F16` → `f16`).
fn snake_case(ident: &Ident) -> String {
    let mut out = String::new();
    for (index, c) in ident.to_string().chars().enumerate() {
        if c.is_uppercase() {
            if index > 0 {
                out.push('_');
            }
            out.extend(c.to_lowercase());
        } else {
            out.push(c);
        }
    }
    out
}

fn choice(input: &DeriveInput) -> syn::Result<Tokens> {
    let name = &input.ident;
    let Data::Enum(data) = &input.data else {
        return Err(syn::Error::new(input.span(), "Choice derives only for enums of unit variants"));
    };
    let mut words = Vec::new();
    let mut variants = Vec::new();
    for variant in &data.variants {
        if !matches!(variant.fields, Fields::Unit) {
            return Err(syn::Error::new(variant.span(), "Choice variants carry no data"));
        }
        let mut word = snake_case(&variant.ident);
        for attribute in variant.attrs.iter().filter(|a| a.path().is_ident("choice")) {
            attribute.parse_nested_meta(|meta| {
                if meta.path.is_ident("name") {
                    word = meta.value()?.parse::<LitStr>()?.value();
                    Ok(())
                } else {
                    Err(meta.error("expected name = \"...\""))
                }
            })?;
        }
        words.push(word);
        variants.push(&variant.ident);
    }
    let Some(first) = variants.first() else {
        return Err(syn::Error::new(input.span(), "a Choice needs at least one variant"));
    };
    Ok(quote! {
        impl ::ssm_core::Choice for #name {
            const OPTIONS: &'static [&'static str] = &[#(#words),*];
            const FIRST: Self = Self::#first;

            fn from_name(word: &str) -> ::core::option::Option<Self> {
                match word {
                    #(#words => ::core::option::Option::Some(Self::#variants),)*
                    _ => ::core::option::Option::None,
                }
            }

            fn name(self) -> &'static str {
                match self {
                    #(Self::#variants => #words,)*
                }
            }
        }
    })
}

/// Derives `ssm_core::UniformStruct` for a `#[repr(C)]` struct uploaded as a
/// uniform: its size and the offset of every field, so that a test can check
/// them against the WGSL struct the shaders declare (naga reflection), and the
/// WGSL declaration itself (`UniformStruct::WGSL`), so that the struct is
/// written once: a technique hands it to its shaders as an importable file.
///
/// The WGSL struct is named by `#[wgsl(name = "...")]`, else by the Rust name
/// without a trailing `Uniform`; each field's doc comment becomes its WGSL
/// comment; shaders import it as `// #import rust/<WGSL name>`
/// (`UniformStruct::WGSL_IMPORT`). Field types: `u32`, `i32`, `f32`, arrays of 2 to 4 of them
/// (`vecN`), `[[f32; R]; C]` (`matCxR<f32>`), and glam's `Vec2`–`Vec4`,
/// `UVec2`–`UVec4`, `IVec2`–`IVec4` and `Mat4`. Fields whose names start with
/// `pad` or `_pad` are padding (they keep their WGSL member, so that both
/// sides have one size).
#[proc_macro_derive(UniformStruct, attributes(wgsl))]
pub fn derive_uniform(input: TokenStream) -> TokenStream {
    let input = syn::parse_macro_input!(input as DeriveInput);
    uniform(&input).unwrap_or_else(syn::Error::into_compile_error).into()
}

fn uniform(input: &DeriveInput) -> syn::Result<Tokens> {
    let name = &input.ident;
    let Data::Struct(data) = &input.data else {
        return Err(syn::Error::new(input.span(), "UniformStruct derives only for structs with named fields"));
    };
    let Fields::Named(fields) = &data.fields else {
        return Err(syn::Error::new(input.span(), "UniformStruct derives only for structs with named fields"));
    };
    let names: Vec<String> = fields.named.iter().filter_map(|f| f.ident.as_ref().map(ToString::to_string)).collect();
    let idents: Vec<&Ident> = fields.named.iter().filter_map(|f| f.ident.as_ref()).collect();
    let rust_name = name.to_string();
    let wgsl_name = wgsl_struct_name(input)?;
    let mut wgsl = format!("struct {wgsl_name} {{\n");
    for field in &fields.named {
        let doc = doc_lines(&field.attrs);
        for line in doc {
            wgsl.push_str(&format!("    //{}{line}\n", if line.is_empty() { "" } else { " " }));
        }
        let ty = wgsl_type(&field.ty).ok_or_else(|| {
            syn::Error::new(field.ty.span(), "UniformStruct: no WGSL type for this field (u32, i32, f32, arrays of 2 to 4 of them, [[f32; R]; C], glam vectors and Mat4)")
        })?;
        let field_name = field.ident.as_ref().map(ToString::to_string).unwrap_or_default();
        wgsl.push_str(&format!("    {field_name}: {ty},\n"));
    }
    wgsl.push_str("}\n");
    let wgsl_import = format!("{}{wgsl_name}", "rust/");
    Ok(quote! {
        impl ::ssm_core::UniformStruct for #name {
            const LAYOUT: ::ssm_core::RustLayout = ::ssm_core::RustLayout {
                name: #rust_name,
                size: ::core::mem::size_of::<Self>(),
                fields: &[#((#names, ::core::mem::offset_of!(Self, #idents))),*],
            };
            const WGSL_NAME: &'static str = #wgsl_name;
            const WGSL_IMPORT: &'static str = #wgsl_import;
            const WGSL: &'static str = #wgsl;
        }
    })
}

/// The WGSL struct's name: `#[wgsl(name = "...")]`, else the Rust name less a trailing `Uniform`.
fn wgsl_struct_name(input: &DeriveInput) -> syn::Result<String> {
    let mut name = None;
    for attribute in input.attrs.iter().filter(|a| a.path().is_ident("wgsl")) {
        attribute.parse_nested_meta(|meta| {
            if meta.path.is_ident("name") {
                let value: LitStr = meta.value()?.parse()?;
                name = Some(value.value());
                Ok(())
            } else {
                Err(meta.error("expected name"))
            }
        })?;
    }
    let rust = input.ident.to_string();
    Ok(name.unwrap_or_else(|| rust.strip_suffix("Uniform").filter(|s| !s.is_empty()).unwrap_or(&rust).to_owned()))
}

/// The lines of a doc comment as written (a blank line kept, leading space trimmed).
fn doc_lines(attrs: &[syn::Attribute]) -> Vec<String> {
    attrs
        .iter()
        .filter(|a| a.path().is_ident("doc"))
        .filter_map(|a| match &a.meta {
            syn::Meta::NameValue(nv) => match &nv.value {
                Expr::Lit(syn::ExprLit { lit: Lit::Str(text), .. }) => {
                    let text = text.value();
                    Some(text.strip_prefix(' ').unwrap_or(&text).trim_end().to_owned())
                }
                _ => None,
            },
            _ => None,
        })
        .collect()
}

/// The WGSL type of a uniform field's Rust type, where there is one.
fn wgsl_type(ty: &Type) -> Option<String> {
    let scalar = |ty: &Type| match type_name(ty).as_deref() {
        Some(name @ ("u32" | "i32" | "f32")) if matches!(ty, Type::Path(_)) => Some(name.to_owned()),
        _ => None,
    };
    let length = |array: &syn::TypeArray| match &array.len {
        Expr::Lit(syn::ExprLit { lit: Lit::Int(n), .. }) => n.base10_parse::<u32>().ok(),
        _ => None,
    };
    match ty {
        Type::Path(_) => scalar(ty).or_else(|| {
            let name = type_name(ty)?;
            let (element, size) = match name.as_str() {
                "Vec2" | "Vec3" | "Vec4" => ("f32", &name[3..]),
                "UVec2" | "UVec3" | "UVec4" => ("u32", &name[4..]),
                "IVec2" | "IVec3" | "IVec4" => ("i32", &name[4..]),
                "Mat4" => return Some("mat4x4<f32>".to_owned()),
                _ => return None,
            };
            Some(format!("vec{size}<{element}>"))
        }),
        Type::Array(array) => {
            let n = length(array).filter(|n| (2..=4).contains(n))?;
            if let Some(element) = scalar(&array.elem) {
                return Some(format!("vec{n}<{element}>"));
            }
            match array.elem.as_ref() {
                Type::Array(column) if scalar(&column.elem).as_deref() == Some("f32") => {
                    let rows = length(column).filter(|r| (2..=4).contains(r))?;
                    Some(format!("mat{n}x{rows}<f32>"))
                }
                _ => None,
            }
        }
        _ => None,
    }
}
