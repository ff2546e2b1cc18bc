//! A pass's shader specialised to one variant before the driver sees it.
//!
//! A pass file holds every variant's code behind `override` constants
//! (`if SHADE { … }`). Given those constants as they are, the driver would still take in,
//! inline and optimise the whole file for each pipeline, and on a CPU driver such as
//! lavapipe that front-end work is most of a first frame. [`specialise`] resolves the
//! overrides on naga's IR, keeps only the branches the variant takes, and drops the
//! functions, globals and types nothing left uses: the driver compiles only what the
//! variant runs. What a variant computes is unchanged: only code the constants rule out
//! goes, and the `let` names (debug names in the driver's input) with it.

use naga::back::pipeline_constants::process_overrides;
use naga::back::PipelineConstants;
use naga::{
    BinaryOperator, Block, Expression, Function, Handle, Literal, LocalVariable, Module,
    ShaderStage, Span, Statement, UnaryOperator,
};
use std::collections::{HashMap, VecDeque};

use crate::error::{Error, Result};

/// A composed pass file, parsed and validated once per device.
pub(crate) struct Parsed {
    module: Module,
    info: naga::valid::ModuleInfo,
}

/// Parses and validates the composed WGSL of pass `file`.
pub(crate) fn parse(file: &str, source: &str) -> Result<Parsed> {
    let module = naga::front::wgsl::parse_str(source)
        .map_err(|e| Error::Gpu(format!("shader {file}: {}", e.emit_to_string(source))))?;
    let info = naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::all(),
    )
    .validate(&module)
    .map_err(|e| Error::Gpu(format!("shader {file}: {}", e.emit_to_string(source))))?;
    Ok(Parsed { module, info })
}

/// `parsed`'s compute entry point `entry` with the override `constants`, holding only the
/// code that variant runs: no overrides, no other entry point, each `if` the constants
/// decide replaced by its branch, then everything unused removed (`naga::compact`). The
/// named expressions go too, since a removed branch's names would keep its expressions.
pub(crate) fn specialise(
    file: &str,
    parsed: &Parsed,
    entry: &str,
    constants: &[(&'static str, f64)],
) -> Result<Module> {
    let values: PipelineConstants = constants
        .iter()
        .map(|&(name, v)| (name.to_string(), v))
        .collect();
    let (module, _) = process_overrides(
        &parsed.module,
        &parsed.info,
        Some((ShaderStage::Compute, entry)),
        &values,
    )
    .map_err(|e| Error::Gpu(format!("shader {file}, entry {entry}: {e}")))?;
    let mut module = module.into_owned();
    let prune_function = |module: &Module, f: &mut Function| {
        let mut pruner = Pruner {
            module,
            expressions: &f.expressions,
            stored: HashMap::new(),
            loaded: HashMap::new(),
        };
        pruner.prune(&mut f.body);
        f.named_expressions.clear();
    };
    // `process_overrides` kept only `entry` among the entry points.
    let mut functions = std::mem::take(&mut module.functions);
    for (_, f) in functions.iter_mut() {
        prune_function(&module, f);
    }
    module.functions = functions;
    let mut entries = std::mem::take(&mut module.entry_points);
    for e in entries.iter_mut() {
        prune_function(&module, &mut e.function);
    }
    module.entry_points = entries;
    naga::compact::compact(&mut module, naga::compact::KeepUnused::No);
    Ok(module)
}

/// Prunes one function: what its boolean expressions are known to be once the overrides
/// have values.
///
/// naga lowers `a && b` and `a || b` to a local variable that each branch of an `if a`
/// stores to, and tests a load of that local. So a store of a known value, followed only
/// by `Emit`s, makes the loads those `Emit`s evaluate known too.
struct Pruner<'a> {
    module: &'a Module,
    expressions: &'a naga::Arena<Expression>,
    /// Locals whose last store, with nothing but `Emit`s after it, was a known value.
    stored: HashMap<Handle<LocalVariable>, bool>,
    /// Loads evaluated while their local held a known value.
    loaded: HashMap<Handle<Expression>, bool>,
}

impl Pruner<'_> {
    /// The value of a boolean expression, where the constants decide it.
    fn boolean(&self, e: Handle<Expression>) -> Option<bool> {
        match self.expressions[e] {
            Expression::Literal(Literal::Bool(b)) => Some(b),
            Expression::Constant(c) => {
                match self.module.global_expressions[self.module.constants[c].init] {
                    Expression::Literal(Literal::Bool(b)) => Some(b),
                    _ => None,
                }
            }
            Expression::Load { .. } => self.loaded.get(&e).copied(),
            Expression::Unary {
                op: UnaryOperator::LogicalNot,
                expr,
            } => self.boolean(expr).map(|b| !b),
            Expression::Binary { op, left, right } => {
                let (l, r) = (self.boolean(left), self.boolean(right));
                match op {
                    BinaryOperator::LogicalAnd => match (l, r) {
                        (Some(false), _) | (_, Some(false)) => Some(false),
                        (Some(true), Some(true)) => Some(true),
                        _ => None,
                    },
                    BinaryOperator::LogicalOr => match (l, r) {
                        (Some(true), _) | (_, Some(true)) => Some(true),
                        (Some(false), Some(false)) => Some(false),
                        _ => None,
                    },
                    _ => None,
                }
            }
            _ => None,
        }
    }

    /// The local a pointer expression names, if it is one.
    fn local(&self, pointer: Handle<Expression>) -> Option<Handle<LocalVariable>> {
        match self.expressions[pointer] {
            Expression::LocalVariable(l) => Some(l),
            _ => None,
        }
    }

    /// Replaces each `if` whose condition is known by the branch taken, in `block` and the
    /// blocks inside it.
    fn prune(&mut self, block: &mut Block) {
        let mut queue: VecDeque<(Statement, Span)> =
            std::mem::take(block).span_into_iter().collect();
        self.stored.clear();
        while let Some((mut statement, span)) = queue.pop_front() {
            match &mut statement {
                Statement::Emit(range) => {
                    for e in range.clone() {
                        if let Expression::Load { pointer } = self.expressions[e] {
                            let known = self.local(pointer).and_then(|l| self.stored.get(&l));
                            if let Some(&b) = known {
                                self.loaded.insert(e, b);
                            }
                        }
                    }
                    block.push(statement, span);
                    continue;
                }
                Statement::Store { pointer, value } => {
                    if let Some(l) = self.local(*pointer) {
                        let value = self.boolean(*value);
                        self.stored.clear();
                        if let Some(b) = value {
                            self.stored.insert(l, b);
                        }
                        block.push(statement, span);
                        continue;
                    }
                }
                Statement::If {
                    condition,
                    accept,
                    reject,
                } => {
                    if let Some(taken) = self.boolean(*condition) {
                        let taken = std::mem::take(if taken { accept } else { reject });
                        let taken: Vec<_> = taken.span_into_iter().collect();
                        for item in taken.into_iter().rev() {
                            queue.push_front(item);
                        }
                        continue;
                    }
                    self.prune(accept);
                    self.prune(reject);
                }
                Statement::Block(inner) => self.prune(inner),
                Statement::Switch { cases, .. } => {
                    for case in cases.iter_mut() {
                        self.prune(&mut case.body);
                    }
                }
                Statement::Loop {
                    body, continuing, ..
                } => {
                    self.prune(body);
                    self.prune(continuing);
                }
                _ => {}
            }
            self.stored.clear();
            block.push(statement, span);
        }
        self.stored.clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn function_names(m: &Module) -> Vec<String> {
        let mut names: Vec<String> = m
            .functions
            .iter()
            .filter_map(|(_, f)| f.name.clone())
            .collect();
        names.sort();
        names
    }

    fn validates(m: &Module) {
        naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::all(),
        )
        .validate(m)
        .unwrap_or_else(|e| panic!("the specialised module does not validate: {e:?}"));
    }

    const SOURCE: &str = "
        override SHADE: bool;
        override STEPS: u32 = 2u;
        @group(0) @binding(0) var<storage, read_write> out: array<f32>;
        @group(0) @binding(1) var<storage, read> lights: array<f32>;
        fn lit(x: f32) -> f32 { return x * lights[0]; }
        fn plain(x: f32) -> f32 { return x + 1.0; }
        @compute @workgroup_size(1) fn main() {
            var v = out[0];
            if SHADE && v > 0.0 { v = lit(v); } else { v = plain(v); }
            if !SHADE { v = v * 3.0; }
            for (var i = 0u; i < STEPS; i++) { if SHADE || i > 0u { v = v + 1.0; } }
            out[0] = v;
        }
        @compute @workgroup_size(1) fn other() { out[1] = lit(2.0); }";

    #[test]
    fn an_untaken_branch_and_what_only_it_uses_are_gone() {
        let parsed = parse("test.wgsl", SOURCE).unwrap();
        let off = specialise("test.wgsl", &parsed, "main", &[("SHADE", 0.0)]).unwrap();
        validates(&off);
        assert_eq!(function_names(&off), ["plain"]);
        assert_eq!(
            off.global_variables.len(),
            1,
            "the lights are unused without SHADE"
        );
        assert_eq!(off.entry_points.len(), 1);
        assert!(off.overrides.is_empty());

        // `SHADE && v > 0.0` is not decided by SHADE = 1: both branches stay.
        let on = specialise(
            "test.wgsl",
            &parsed,
            "main",
            &[("SHADE", 1.0), ("STEPS", 4.0)],
        );
        let on = on.unwrap();
        validates(&on);
        assert_eq!(function_names(&on), ["lit", "plain"]);
        assert_eq!(on.global_variables.len(), 2);
    }

    #[test]
    fn a_missing_constant_is_an_error() {
        let parsed = parse("test.wgsl", SOURCE).unwrap();
        let e = specialise("test.wgsl", &parsed, "main", &[]).unwrap_err();
        assert!(e.to_string().contains("test.wgsl"), "{e}");
    }

    /// Every pass with all its boolean overrides off, then all on (numbers at their
    /// defaults, or 1): the specialised module validates.
    #[test]
    fn every_pass_specialises_to_a_valid_module() {
        for &file in crate::gpu::shaders::PASSES {
            let parsed = parse(file, &crate::gpu::shaders::compose(file)).unwrap();
            for on in [false, true] {
                let constants: Vec<(&'static str, f64)> = parsed
                    .module
                    .overrides
                    .iter()
                    .filter_map(|(_, o)| {
                        let name: &'static str = o.name.clone()?.leak();
                        let boolean = matches!(
                            parsed.module.types[o.ty].inner,
                            naga::TypeInner::Scalar(naga::Scalar::BOOL)
                        );
                        match (boolean, o.init) {
                            (true, _) => Some((name, if on { 1.0 } else { 0.0 })),
                            (false, Some(_)) => None,
                            (false, None) => Some((name, 1.0)),
                        }
                    })
                    .collect();
                for entry in parsed.module.entry_points.iter().map(|e| e.name.as_str()) {
                    let m = specialise(file, &parsed, entry, &constants)
                        .unwrap_or_else(|e| panic!("{file} {entry}: {e}"));
                    validates(&m);
                }
            }
        }
    }
}
