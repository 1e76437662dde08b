!> The scene as written for any N, read from files as a user's are: input_records expands
!> the chain shorthand and the &contact / &spring records into the model's record layout
!> (issue 19), and a tutorial two-body scene gives today's contacts and springs as records.
program test_chain
  use, intrinsic :: iso_fortran_env, only: int64
  use impact1d_kinds, only: wp
  use impact1d_error, only: error_type, fmt
  use impact1d_scene, only: scene_input, is_nbody
  use impact1d_io, only: read_scene_file
  use impact1d_chain, only: input_records, mechanism_records, n_bodies_of, alias_slot, slot_of, validate_chain
  use impact1d_fields, only: n_arrays, alias_name
  use testing, only: check, finish
  implicit none
  character(len=*), parameter :: path = 'output/test_chain_scene.nml'
  type(mechanism_records) :: r
  integer :: j, i
  integer(int64), parameter :: samples(9) = [0_int64, 7_int64, -7_int64, 10_int64, -10_int64, 1234567890_int64, &
    huge(0_int64), -huge(0_int64), -huge(0_int64) - 1_int64]
  character(len=32) :: written

  ! The tutorial's case 3 with springs: left, right, slot; k1 (0,1), k2 (0,2), k12 (1,2).
  call records_of([character(len=80) :: &
    '&bodies m1 = 1.0, m2 = 2.0 /', '&initial x1 = 1.0, x2 = 2.5 /', &
    '&walls x_left = 0.0, r_left = 0.5, x_right = 10.0 /', '&link d_max = 2.0, r_max = 0.25 /', &
    '&springs k1 = 3, x1_rest = 1, k2 = 4, x2_rest = 2.5, c12 = 0.5 /', '&run t_end = 1, dt = 1e-3 /'], r, 2)
  call check(r%n_contacts == 3, 'two bodies: three contacts')
  call check(all(r%contact_name == [character(len=8) :: 'left', 'right', 'slot']), 'two bodies: names')
  call check(all(r%contact_body == reshape([0, 1, 0, 2, 1, 2], [2, 3])), 'two bodies: ends')
  call check(all(r%contact_has .eqv. reshape([.true., .false., .false., .true., .true., .true.], [2, 3])), &
    'two bodies: limits present')
  call check(all(r%contact_limit(:, 3) == [0.0_wp, 2.0_wp]) .and. r%contact_limit(1, 1) == 0.0_wp .and. &
    r%contact_limit(2, 2) == 10.0_wp, 'two bodies: limits (the meeting at d_min = 0)')
  call check(r%contact_restitution(1, 1) == 0.5_wp .and. all(r%contact_restitution(:, 3) == [1.0_wp, 0.25_wp]), &
    'two bodies: restitutions')
  call check(r%n_elements == 3 .and. all(r%element_body == reshape([0, 1, 0, 2, 1, 2], [2, 3])), &
    'two bodies: elements k1, k2, k12 in order')
  call check(all(r%element_k == [3.0_wp, 4.0_wp, 0.0_wp]) .and. all(r%element_rest == [1.0_wp, 2.5_wp, 0.0_wp]) &
    .and. all(r%element_c == [0.0_wp, 0.0_wp, 0.5_wp]), 'two bodies: k, rest, c')

  ! Four bodies: walls on bodies 1 and 4, links 1 and 3 meet (r_meet), link 2 replaced by a
  ! &contact on (3, 2); a ground stop written with b = 0 turned round; springs in order.
  call records_of([character(len=100) :: &
    '&bodies m = 4*1.0 /', '&initial x = 0.0, 1.0, 2.0, 3.0 /', '&walls x_left = -1.0, x_right = 5.0 /', &
    '&link r_meet = 0.5 /', '&springs k = 2*1.0, 0, 0, x_rest = 4*0.0, k_link = 3*2.0, d_rest = 3*1.0 /', &
    '&contact a = 3, b = 2, d_min = -2.0, d_max = -0.5, r_max = 0.0 /', &
    '&contact a = 4, b = 0, d_min = -4.0, r_min = 0.25, name = ''stop4'' /', &
    '&spring a = 4, b = 0, k = 7.0, d_rest = -3.0 /', '&run t_end = 1, dt = 1e-3 /'], r, 4)
  call check(r%n_contacts == 6, 'chain: six contacts')
  call check(all(r%contact_name == [character(len=8) :: 'left', 'right', 'link1', 'link3', 'contact1', 'stop4']), &
    'chain: names and order (walls, links, records)')
  call check(all(r%contact_body(:, 2) == [0, 4]) .and. all(r%contact_body(:, 4) == [3, 4]), &
    'chain: right wall on body N, link 3 on (3, 4)')
  call check(all(r%contact_restitution(1, 3:4) == 0.5_wp), 'chain: the meetings take r_meet')
  call check(all(r%contact_body(:, 5) == [3, 2]) .and. all(r%contact_limit(:, 5) == [-2.0_wp, -0.5_wp]) .and. &
    r%contact_restitution(2, 5) == 0.0_wp, 'chain: a record on a neighbour pair replaces the meeting')
  call check(all(r%contact_body(:, 6) == [0, 4]) .and. all(r%contact_has(:, 6) .eqv. [.false., .true.]) .and. &
    r%contact_limit(2, 6) == 4.0_wp .and. r%contact_restitution(2, 6) == 0.25_wp, &
    'chain: b = 0 turned round (x4 <= 4)')
  call check(r%n_elements == 8, 'chain: 4 ground springs, 3 link springs, 1 record')
  call check(all(r%element_body(:, 5) == [1, 2]) .and. all(r%element_body(:, 7) == [3, 4]) .and. &
    all(r%element_body(:, 8) == [0, 4]) .and. r%element_rest(8) == 3.0_wp .and. r%element_k(8) == 7.0_wp, &
    'chain: link springs, then the record turned round')

  ! The table of the tutorial's names (element reads two-body arrays through it) names the
  ! slots a search of the names finds.
  do j = 1, n_arrays
    do i = 1, 3
      call check(alias_slot(j, i) == slot_of(alias_name(j, i)), 'alias_slot: ' // trim(alias_name(j, i)))
    end do
  end do

  ! fmt's integers (the labels of check_start's messages), digit by digit as '(i0)' writes them.
  do j = 1, size(samples)
    write(written, '(i0)') samples(j)
    call check(fmt(samples(j)) == written, 'fmt(int64): ' // trim(written))
    if (samples(j) >= -huge(0) .and. samples(j) <= huge(0)) &
      call check(fmt(int(samples(j))) == written, 'fmt(int): ' // trim(written))
  end do
  call check(fmt(-huge(0) - 1) == '-2147483648', 'fmt(int): -huge - 1')
  call finish('test_chain')

contains

  !> Write lines to a scene file, read it (as the CLI does) and expand its records; n is the
  !> number of bodies it must have.
  subroutine records_of(lines, records, n)
    character(len=*), intent(in) :: lines(:)
    type(mechanism_records), intent(out) :: records
    integer, intent(in) :: n
    type(mechanism_records) :: checked
    type(scene_input) :: input
    type(error_type), allocatable :: error
    integer :: unit, k
    open(newunit=unit, file=path, status='replace', action='write')
    do k = 1, size(lines)
      write(unit, '(a)') trim(lines(k))
    end do
    close(unit)
    call read_scene_file(path, input, error)
    if (allocated(error)) then
      print '(a)', 'records_of: ' // error%message
      error stop 1
    end if
    open(newunit=unit, file=path, status='old')
    close(unit, status='delete')
    call check(n_bodies_of(input) == n, 'records_of: N')
    call check(is_nbody(input) .eqv. n > 2, 'records_of: needs the N-body engine')
    call input_records(input, records)
    ! validate_chain hands back the records it checked (prepare_scene builds the scene from
    ! them): the same as input_records'.
    call validate_chain(input, error, checked)
    call check(.not. allocated(error), 'records_of: validate_chain')
    call check(checked%n_contacts == records%n_contacts .and. checked%n_elements == records%n_elements, &
      'validate_chain: record counts')
    call check(all(checked%contact_body == records%contact_body) .and. all(checked%contact_has .eqv. &
      records%contact_has) .and. all(checked%contact_limit == records%contact_limit) .and. &
      all(checked%contact_restitution == records%contact_restitution) .and. &
      all(checked%contact_name == records%contact_name), 'validate_chain: contact records')
    call check(all(checked%element_body == records%element_body) .and. all(checked%element_k == records%element_k) &
      .and. all(checked%element_c == records%element_c) .and. all(checked%element_rest == records%element_rest), &
      'validate_chain: element records')
  end subroutine records_of
end program test_chain
