module LowerCase
    ! Keywords and instructions in lower case, as some editors save them.
    const robtarget pA := [[375, 0, 540], [0, 0, 1, 0], [0, 0, 0, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    const robtarget pB := [[300, 150, 400], [0, 0, 1, 0], [0, 0, 0, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    const num nWait := 0.4;
    proc main()
        while true do
            movej pA, v1000, z50, tool0;
            movel pB, v300, fine, tool0;
            waittime nWait;
            for i from 1 to 2 do
                movel Offs(pB, 0, 0, 20 * i), v200, z5, tool0;
            endfor
        endwhile
    endproc
endmodule
