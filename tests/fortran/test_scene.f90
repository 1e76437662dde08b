!> The model's contact records and the rows made from them (docs/nbody-plan.md section 1):
!> the tutorial's walls and slot in record order, their rows in the order the engine's ties
!> need (left, right, slot_min, slot_max), gaps with the tutorial's signs, names, partners.
program test_scene
  use impact1d_kinds, only: wp
  use impact1d_scene, only: scene_type
  use testing, only: check, finish, two_body
  implicit none
  type(scene_type) :: scene

  call two_body('m2 = 2, x_left = -1, r_left = 0.5, x_right = 5, d_min = 0.25, d_max = 2, r_max = 0.75', scene)
  call check(scene%n_contacts == 3, 'walls and slot: three records')
  call check(all(scene%contact_name == [character(len=8) :: 'left', 'right', 'slot']), 'record names')
  call check(all(scene%contact_body == reshape([0, 1, 0, 2, 1, 2], [2, 3])), 'record ends')
  call check(all(scene%contact_has .eqv. reshape([.true., .false., .false., .true., .true., .true.], [2, 3])), &
    'limits present: left lower, right upper, slot both')
  call check(scene%n_rows == 4, 'four rows')
  call check(all(scene%row_name == [character(len=8) :: 'left', 'right', 'slot_min', 'slot_max']), 'row names')
  call check(all(scene%row_normal == reshape([0.0_wp, 1.0_wp, 0.0_wp, -1.0_wp, -1.0_wp, 1.0_wp, 1.0_wp, -1.0_wp], &
    [2, 4])), 'row normals: ground ends 0, lower (-1, 1), upper (1, -1)')
  call check(all(scene%row_offset == [1.0_wp, 5.0_wp, -0.25_wp, 2.0_wp]), 'row offsets: -x_left, x_right, -d_min, d_max')
  call check(all(scene%row_restitution == [0.5_wp, 1.0_wp, 1.0_wp, 0.75_wp]), 'row restitutions, 1 by default')
  call check(all(scene%row_contact == [1, 2, 3, 3]), 'rows name their records')
  call check(all(scene%row_partner == 0), 'no rigid link: no partners')

  ! Two bodies with nothing named: the slot's meeting alone, still suffixed.
  call two_body('', scene)
  call check(scene%n_contacts == 1 .and. scene%n_rows == 1, 'two bodies: the meeting only')
  call check(scene%row_name(1) == 'slot_min' .and. scene%row_offset(1) == 0.0_wp, 'the meeting: slot_min, d_min = 0')

  ! A rigid link: its limits are each other's partner.
  call two_body('d_min = 1, d_max = 1', scene)
  call check(all(scene%row_partner == [2, 1]), 'rigid link: partners')

  ! One body: the right wall holds body 1; no slot.
  call two_body('x_right = 3', scene, one_body=.true.)
  call check(scene%n_contacts == 1 .and. all(scene%contact_body(:, 1) == [0, 1]), 'one body: right wall on body 1')
  call check(scene%row_name(1) == 'right' .and. all(scene%row_normal(:, 1) == [0.0_wp, -1.0_wp]), &
    'one body: the right row')

  ! Elements: records in the order k1, k2, k12 where the scene names them.
  call two_body('k1 = 2, x1_rest = 0.5, k12 = 3, d_rest = 1, c12 = 0.25, c2 = 0.5', scene)
  call check(scene%n_elements == 3 .and. all(scene%element_body == reshape([0, 1, 0, 2, 1, 2], [2, 3])), &
    'elements k1, k2 (a damper alone), k12 in order')
  call check(all(scene%element_k == [2.0_wp, 0.0_wp, 3.0_wp]) .and. all(scene%element_c == [0.0_wp, 0.5_wp, 0.25_wp]) &
    .and. all(scene%element_rest == [0.5_wp, 0.0_wp, 1.0_wp]), 'element coefficients and rest lengths')
  call two_body('', scene)
  call check(scene%n_elements == 0 .and. .not. scene%springs%present, 'no springs: no elements')
  call finish('test_scene')
end program test_scene
