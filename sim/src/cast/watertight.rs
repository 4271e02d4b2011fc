//! Watertight ray/triangle intersection (Woop, Benthin and Wald, JCGT 2013).
//! TODO(caster helper): implement; stub until then.
