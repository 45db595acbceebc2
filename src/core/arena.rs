//! Generational arena: objects addressed by one `u64` id that is checked on every access.
//!
//! Id layout (the C ABI's `kdw_*_id`): bits 0..28 slot index, 28..44 generation (never 0, so no valid id
//! is 0), 44..48 object kind, 48..64 the owning engine's salt. A destroyed object's id goes stale when
//! its slot's generation moves on; an id of another kind or another engine never matches. (Slot maps from
//! crates.io pack only index and version, so they cannot reject foreign ids: this layout is part of our ABI.)

use std::marker::PhantomData;

const INDEX_BITS: u32 = 28;
const GENERATION_BITS: u32 = 16;
const KIND_BITS: u32 = 4;
const INDEX_MASK: u64 = (1 << INDEX_BITS) - 1;
const GENERATION_MASK: u64 = (1 << GENERATION_BITS) - 1;
const KIND_MASK: u64 = (1 << KIND_BITS) - 1;
const GENERATION_SHIFT: u32 = INDEX_BITS;
const KIND_SHIFT: u32 = INDEX_BITS + GENERATION_BITS;
const SALT_SHIFT: u32 = KIND_SHIFT + KIND_BITS;

/// Most objects of one kind an engine can hold at once.
pub const MAX_OBJECTS: usize = 1 << INDEX_BITS;

/// The kinds of object that have ids.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    Chain = 1,
    ViewShape = 2,
    Collider = 3,
}

/// A typed id. `T` only keeps ids of different kinds apart in Rust; the kind bits do it at run time.
pub struct Id<T> {
    bits: u64,
    _kind: PhantomData<fn() -> T>,
}

impl<T> std::fmt::Debug for Id<T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Id({:#x})", self.bits)
    }
}
impl<T> Clone for Id<T> {
    fn clone(&self) -> Self {
        *self
    }
}
impl<T> Copy for Id<T> {}
impl<T> PartialEq for Id<T> {
    fn eq(&self, other: &Self) -> bool {
        self.bits == other.bits
    }
}
impl<T> Eq for Id<T> {}

impl<T> Id<T> {
    pub const NULL: Self = Self::from_bits(0);

    pub const fn from_bits(bits: u64) -> Self {
        Self { bits, _kind: PhantomData }
    }

    pub const fn to_bits(self) -> u64 {
        self.bits
    }

    fn index(self) -> usize {
        (self.bits & INDEX_MASK) as usize
    }

    fn generation(self) -> u16 {
        ((self.bits >> GENERATION_SHIFT) & GENERATION_MASK) as u16
    }
}

struct Slot<T> {
    generation: u16,
    value: Option<T>,
}

pub struct Arena<T> {
    slots: Vec<Slot<T>>,
    free: Vec<u32>,
    tag: u64,
    len: usize,
}

impl<T> Arena<T> {
    pub fn new(kind: Kind, salt: u16) -> Self {
        let tag = ((salt as u64) << SALT_SHIFT) | ((kind as u64 & KIND_MASK) << KIND_SHIFT);
        Self { slots: Vec::new(), free: Vec::new(), tag, len: 0 }
    }

    pub fn len(&self) -> usize {
        self.len
    }

    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    fn id_of(&self, index: usize) -> Id<T> {
        let generation = self.slots[index].generation as u64;
        Id::from_bits(self.tag | (generation << GENERATION_SHIFT) | index as u64)
    }

    /// Checks space first so that callers can validate everything before mutating anything.
    pub fn has_room(&self) -> bool {
        !self.free.is_empty() || self.slots.len() < MAX_OBJECTS
    }

    /// Inserts `value`; `None` when the arena is full (see [`has_room`](Self::has_room)).
    pub fn insert(&mut self, value: T) -> Option<Id<T>> {
        let index = match self.free.pop() {
            Some(index) => index as usize,
            None if self.slots.len() < MAX_OBJECTS => {
                self.slots.push(Slot { generation: 1, value: None });
                self.slots.len() - 1
            }
            None => return None,
        };
        self.slots[index].value = Some(value);
        self.len += 1;
        Some(self.id_of(index))
    }

    /// Slot index of a live id: stable for the object's lifetime, reused after removal.
    pub fn index_of(&self, id: Id<T>) -> Option<usize> {
        if id.bits & !(INDEX_MASK | (GENERATION_MASK << GENERATION_SHIFT)) != self.tag {
            return None;
        }
        let slot = self.slots.get(id.index())?;
        (slot.generation == id.generation() && slot.value.is_some()).then_some(id.index())
    }

    pub fn get(&self, id: Id<T>) -> Option<&T> {
        let index = self.index_of(id)?;
        self.slots[index].value.as_ref()
    }

    pub fn get_mut(&mut self, id: Id<T>) -> Option<&mut T> {
        let index = self.index_of(id)?;
        self.slots[index].value.as_mut()
    }

    pub fn at(&self, index: usize) -> Option<&T> {
        self.slots.get(index)?.value.as_ref()
    }

    pub fn at_mut(&mut self, index: usize) -> Option<&mut T> {
        self.slots.get_mut(index)?.value.as_mut()
    }

    /// The live values at `indices` (distinct), all at once; `None` if any is out of range, repeated or empty.
    pub fn many_at_mut<const N: usize>(&mut self, indices: [usize; N]) -> Option<[&mut T; N]> {
        let slots = self.slots.get_disjoint_mut(indices).ok()?;
        if slots.iter().any(|slot| slot.value.is_none()) {
            return None;
        }
        Some(slots.map(|slot| slot.value.as_mut().expect("every slot was checked to be live")))
    }

    pub fn id_at(&self, index: usize) -> Option<Id<T>> {
        self.at(index)?;
        Some(self.id_of(index))
    }

    pub fn remove(&mut self, id: Id<T>) -> Option<T> {
        let index = self.index_of(id)?;
        let slot = &mut self.slots[index];
        let value = slot.value.take();
        // Generation 0 is never used, so no live id is ever 0.
        slot.generation = slot.generation.wrapping_add(1).max(1);
        self.free.push(index as u32);
        self.len -= 1;
        value
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ids_go_stale_and_reject_foreign() {
        let mut a: Arena<i32> = Arena::new(Kind::Chain, 7);
        let b: Arena<i32> = Arena::new(Kind::Chain, 8);
        let views: Arena<i32> = Arena::new(Kind::ViewShape, 7);
        let id = a.insert(5).unwrap();
        assert_ne!(id.to_bits(), 0);
        assert_eq!(a.get(id), Some(&5));
        assert!(b.get(Id::from_bits(id.to_bits())).is_none());
        assert!(views.get(Id::from_bits(id.to_bits())).is_none());
        assert!(a.get(Id::NULL).is_none());
        assert_eq!(a.remove(id), Some(5));
        assert!(a.get(id).is_none());
        let id2 = a.insert(6).unwrap();
        assert_eq!(a.index_of(id2), Some(0));
        assert!(a.get(id).is_none(), "the old id must not reach the reused slot");
        assert_eq!(a.len(), 1);
    }

    #[test]
    fn many_values_at_once_only_when_distinct_in_range_and_live() {
        let mut a: Arena<i32> = Arena::new(Kind::Chain, 7);
        let ids: Vec<Id<i32>> = (0..4).map(|v| a.insert(v).unwrap()).collect();
        let [x, y] = a.many_at_mut([3, 1]).unwrap();
        (*x, *y) = (*x + 10, *y + 10);
        assert_eq!((a.at(3), a.at(1)), (Some(&13), Some(&11)));
        assert!(a.many_at_mut([0, 0]).is_none(), "repeated");
        assert!(a.many_at_mut([0, 4]).is_none(), "out of range");
        a.remove(ids[2]);
        assert!(a.many_at_mut([0, 1, 2, 3]).is_none(), "an empty slot");
        assert_eq!(a.many_at_mut([0, 1, 3]).map(|values| values.map(|v| *v)), Some([0, 11, 13]));
    }
}
